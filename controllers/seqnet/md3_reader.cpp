// Quake III MD3: a 108-byte header ("IDP3", version 15), frames (bounds,
// origin, radius, name), tags, and surfaces, each with its own header,
// triangles and per-frame vertices of int16 x, y, z in 1/64 units plus a
// packed normal we ignore. All surfaces become one mesh (one piece or more
// each); clips come from an animation.cfg in the same folder when present.

#include <filesystem>
#include <sstream>

#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/core/input_file.hpp"
#include "file_bytes.hpp"
#include "mesh_checks.hpp"

namespace animrt::seqnet {
namespace {

// Limits of the Quake III engine (qfiles.h); a file beyond them is corrupt.
constexpr std::int32_t kMaxFrames = 1024;
constexpr std::int32_t kMaxSurfaces = 32;
constexpr std::int32_t kMaxTags = 16;
constexpr std::int32_t kMaxVerts = 4096;
constexpr std::int32_t kMaxTriangles = 8192;
constexpr double kXyzScale = 1.0 / 64.0;
// An animation.cfg is a few kilobytes: 31 lines of four numbers and a header.
constexpr std::uintmax_t kMaxAnimationCfgBytes = std::uintmax_t{1} << 20;

// animation.cfg lines in the order the engine reads them (the last six are
// Team Arena additions some configs carry).
const char* const kAnimationNames[] = {
    "BOTH_DEATH1",   "BOTH_DEAD1",      "BOTH_DEATH2",  "BOTH_DEAD2",     "BOTH_DEATH3",
    "BOTH_DEAD3",    "TORSO_GESTURE",   "TORSO_ATTACK", "TORSO_ATTACK2",  "TORSO_DROP",
    "TORSO_RAISE",   "TORSO_STAND",     "TORSO_STAND2", "LEGS_WALKCR",    "LEGS_WALK",
    "LEGS_RUN",      "LEGS_BACK",       "LEGS_SWIM",    "LEGS_JUMP",      "LEGS_LAND",
    "LEGS_JUMPB",    "LEGS_LANDB",      "LEGS_IDLE",    "LEGS_IDLECR",    "LEGS_TURN",
    "TORSO_GETFLAG", "TORSO_GUARDBASE", "TORSO_PATROL", "TORSO_FOLLOWME", "TORSO_AFFIRMATIVE",
    "TORSO_NEGATIVE"};
constexpr int kAnimationCount =
    static_cast<int>(sizeof kAnimationNames / sizeof kAnimationNames[0]);
constexpr int kTorsoGesture = 6;
constexpr int kLegsWalkCrouched = 13;
constexpr int kLegsTurn = 24;

struct CfgEntry {
  int first = 0;
  int count = 0;
  double fps = 0.0;
  int line = 0;
};

// The clips of animation.cfg that belong to `model` (lower*: BOTH_ and
// LEGS_; upper*: BOTH_ and TORSO_; anything else: none). lower.md3 holds
// no torso frames, so its LEGS_ first frames are shifted down by the
// distance from TORSO_GESTURE to LEGS_WALKCR, as the engine does.
std::vector<Clip> clips_from_cfg(const std::string& cfg, const std::string& model, int frames) {
  std::string stem = std::filesystem::path(model).filename().string();
  const bool lower = stem.rfind("lower", 0) == 0;
  const bool upper = stem.rfind("upper", 0) == 0;
  if (!lower && !upper) return {};
  // No animation.cfg beside the model: no clips. One that is there but is
  // not a readable regular file (a FIFO, a device) is refused by name.
  if (input_file_problem(cfg) == kFileMissing) return {};
  std::istringstream in(read_input_file(cfg, kMaxAnimationCfgBytes));
  std::vector<CfgEntry> entries;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line) && static_cast<int>(entries.size()) < kAnimationCount) {
    ++line_no;
    const std::size_t comment = line.find("//");
    if (comment != std::string::npos) line.resize(comment);
    std::istringstream words(line);
    std::string first;
    if (!(words >> first)) continue;
    if (!(std::isdigit(static_cast<unsigned char>(first[0])) || first[0] == '-'))
      continue;  // sex, footsteps, headoffset, ...
    std::istringstream numbers(line);
    CfgEntry e;
    int looping = 0;
    if (!(numbers >> e.first >> e.count >> looping >> e.fps)) {
      throw InputError(Location{cfg, line_no, 1}, kAnimationNames[entries.size()],
                       "expected four numbers: first frame, frame count, looping frames, fps");
    }
    if (e.count < 0) e.count = -e.count;  // negative counts play backwards: same frames
    e.line = line_no;
    entries.push_back(e);
  }
  const int known = static_cast<int>(entries.size());
  const int skip = known > kLegsWalkCrouched
                       ? entries[kLegsWalkCrouched].first - entries[kTorsoGesture].first
                       : 0;
  std::vector<Clip> clips;
  for (int i = 0; i < known; ++i) {
    const bool both = i < kTorsoGesture;
    const bool legs = i >= kLegsWalkCrouched && i <= kLegsTurn;
    const bool torso = !both && !legs;
    if ((lower && torso) || (upper && legs)) continue;
    CfgEntry e = entries[i];
    if (lower && legs) e.first -= skip;
    // A clip of no frames (merman's LEGS_TURN) names nothing: the engine
    // plays no frame for it, so it is left out rather than refused.
    if (e.count == 0) continue;
    if (e.first < 0 || e.first + e.count > frames) {
      throw InputError(Location{cfg, e.line, 1}, kAnimationNames[i],
                       "frames " + std::to_string(e.first) + ".." +
                           std::to_string(e.first + e.count - 1) + " are outside " + model + "'s " +
                           std::to_string(frames) + " frames");
    }
    clips.push_back(Clip{kAnimationNames[i], e.first, e.count, e.fps});
  }
  return clips;
}

void check_count(const std::string& file, const std::string& key, const char* what,
                 std::int32_t value, std::int32_t low, std::int32_t high) {
  if (value < low || value > high) {
    detail::fail(file, key,
                 std::string(what) + " is " + std::to_string(value) + ", expected " +
                     std::to_string(low) + ".." + std::to_string(high));
  }
}

}  // namespace

MeshSequence read_md3(const std::string& file) {
  const std::vector<std::uint8_t> bytes = detail::read_file_bytes(file);
  const detail::ByteView in(bytes, file);
  in.need(0, 1, 108, "header", "the header");
  if (in.name(0, 4) != "IDP3") detail::fail(file, "header", "not an MD3 file (magic is not IDP3)");
  const std::int32_t version = in.i32(4);
  if (version != 15) {
    detail::fail(file, "header", "MD3 version " + std::to_string(version) + ", expected 15");
  }
  const std::int32_t num_frames = in.i32(76);
  const std::int32_t num_tags = in.i32(80);
  const std::int32_t num_surfaces = in.i32(84);
  const std::int32_t ofs_frames = in.i32(92);
  const std::int32_t ofs_surfaces = in.i32(100);
  check_count(file, "header", "frame count", num_frames, 1, kMaxFrames);
  check_count(file, "header", "tag count", num_tags, 0, kMaxTags);
  check_count(file, "header", "surface count", num_surfaces, 1, kMaxSurfaces);
  if (ofs_frames < 0 || ofs_surfaces < 0) detail::fail(file, "header", "negative offset");
  in.need(static_cast<std::uint64_t>(ofs_frames), static_cast<std::uint64_t>(num_frames), 56,
          "header", "the frames");

  MeshSequence out;
  out.source = file;
  out.frames.assign(static_cast<std::size_t>(num_frames), Positions(3, 0));
  std::vector<int> group;
  std::uint64_t at = static_cast<std::uint64_t>(ofs_surfaces);
  for (std::int32_t s = 0; s < num_surfaces; ++s) {
    const std::string key = "surface " + std::to_string(s);
    in.need(at, 1, 108, key, "the surface header");
    if (in.name(at, 4) != "IDP3") detail::fail(file, key, "surface magic is not IDP3");
    const std::int32_t surface_frames = in.i32(at + 72);
    const std::int32_t verts = in.i32(at + 80);
    const std::int32_t tris = in.i32(at + 84);
    const std::int32_t ofs_tris = in.i32(at + 88);
    const std::int32_t ofs_xyz = in.i32(at + 100);
    const std::int32_t ofs_end = in.i32(at + 104);
    if (surface_frames != num_frames) {
      detail::fail(file, key,
                   std::to_string(surface_frames) + " frames, the header says " +
                       std::to_string(num_frames));
    }
    // An empty surface (no vertices and no triangles, as tony's l_belt)
    // is loaded by the engine and draws nothing; it adds nothing here.
    const bool empty = verts == 0 && tris == 0;
    check_count(file, key, "vertex count", verts, empty ? 0 : 1, kMaxVerts);
    check_count(file, key, "triangle count", tris, empty ? 0 : 1, kMaxTriangles);
    if (ofs_tris < 108 || ofs_xyz < 108 || ofs_end < 108) {
      detail::fail(file, key, "an offset points into the surface header");
    }
    in.need(at + static_cast<std::uint64_t>(ofs_tris), static_cast<std::uint64_t>(tris), 12, key,
            "the triangles");
    in.need(at + static_cast<std::uint64_t>(ofs_xyz),
            static_cast<std::uint64_t>(verts) * static_cast<std::uint64_t>(num_frames), 8, key,
            "the vertices");
    in.need(at, 1, static_cast<std::uint64_t>(ofs_end), key, "the surface");
    const int base = static_cast<int>(group.size());
    for (std::int32_t t = 0; t < tris; ++t) {
      const std::uint64_t tat =
          at + static_cast<std::uint64_t>(ofs_tris) + 12u * static_cast<std::uint64_t>(t);
      std::array<int, 3> tri{};
      for (int k = 0; k < 3; ++k) {
        const std::int32_t index = in.i32(tat + 4u * static_cast<unsigned>(k));
        if (index < 0 || index >= verts) {
          detail::fail(file, key + " triangle " + std::to_string(t),
                       "vertex index " + std::to_string(index) + " is out of range (" +
                           std::to_string(verts) + " vertices)");
        }
        tri[k] = base + index;
      }
      out.triangles.push_back(tri);
    }
    for (std::int32_t f = 0; f < num_frames; ++f) {
      Positions& frame = out.frames[static_cast<std::size_t>(f)];
      frame.conservativeResize(3, base + verts);
      const std::uint64_t fat =
          at + static_cast<std::uint64_t>(ofs_xyz) +
          8u * static_cast<std::uint64_t>(verts) * static_cast<std::uint64_t>(f);
      for (std::int32_t i = 0; i < verts; ++i) {
        for (int k = 0; k < 3; ++k) {
          frame(k, base + i) =
              in.i16(fat + 8u * static_cast<std::uint64_t>(i) + 2u * static_cast<unsigned>(k)) *
              kXyzScale;
        }
        // Bytes 6..7: latitude/longitude of the normal, not used.
      }
    }
    group.insert(group.end(), static_cast<std::size_t>(verts), s);
    at += static_cast<std::uint64_t>(ofs_end);
  }
  detail::merge_coincident(out, group);
  detail::detach_non_manifold(out);
  detail::validate_mesh(out, file);
  const std::filesystem::path cfg = std::filesystem::path(file).parent_path() / "animation.cfg";
  out.clips = clips_from_cfg(cfg.string(), file, num_frames);
  return out;
}

}  // namespace animrt::seqnet
