// Head-pose loaders: Euler CSV, BVH (head relative to torso), marker sets.

#include "animrt/controllers/head/pose_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/joint.hpp"
#include "csv_table.hpp"

namespace animrt::head {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void check_increasing(const CsvTable& table, int time_col) {
  for (std::size_t i = 1; i < table.rows.size(); ++i) {
    if (!(table.rows[i][static_cast<std::size_t>(time_col)] >
          table.rows[i - 1][static_cast<std::size_t>(time_col)])) {
      throw InputError(Location{table.file, table.lines[i], 1}, "time_s",
                       "time must increase from row to row");
    }
  }
}

}  // namespace

Euler PoseTrack::at(double t) const {
  if (times.empty()) return {};
  if (t <= times.front()) return poses.front();
  if (t >= times.back()) return poses.back();
  const auto it = std::upper_bound(times.begin(), times.end(), t);
  const std::size_t i = static_cast<std::size_t>(it - times.begin());
  const double a = (t - times[i - 1]) / (times[i] - times[i - 1]);
  const Euler& p = poses[i - 1];
  const Euler& q = poses[i];
  return {p.yaw + a * (q.yaw - p.yaw), p.pitch + a * (q.pitch - p.pitch),
          p.roll + a * (q.roll - p.roll)};
}

PoseTrack load_euler_csv(const std::string& path) {
  const CsvTable table = read_csv_table(path);
  const int t = table.require("time_s");
  const int y = table.require("yaw_deg");
  const int p = table.require("pitch_deg");
  const int r = table.require("roll_deg");
  check_increasing(table, t);
  PoseTrack track;
  for (const auto& row : table.rows) {
    track.times.push_back(row[static_cast<std::size_t>(t)]);
    track.poses.push_back({row[static_cast<std::size_t>(y)], row[static_cast<std::size_t>(p)],
                           row[static_cast<std::size_t>(r)]});
  }
  return track;
}

void write_euler_csv(const std::string& path, const PoseTrack& track) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw std::runtime_error("cannot write " + path);
  std::fprintf(f, "time_s,yaw_deg,pitch_deg,roll_deg\n");
  for (std::size_t i = 0; i < track.size(); ++i) {
    std::fprintf(f, "%.6f,%.4f,%.4f,%.4f\n", track.times[i], track.poses[i].yaw,
                 track.poses[i].pitch, track.poses[i].roll);
  }
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
}

// ---------------------------------------------------------------- BVH

namespace {

struct BvhJoint {
  std::string name;
  int parent = -1;
  std::vector<std::string> channels;
  int first_channel = 0;  // index into a frame's values
};

class BvhLexer {
 public:
  explicit BvhLexer(const std::string& path) : path_(path), in_(read_input_file(path)) {}
  bool next(std::string& token) {
    while (true) {
      if (pos_ < words_.size()) {
        token = words_[pos_++];
        return true;
      }
      std::string line;
      if (!std::getline(in_, line)) return false;
      ++line_;
      words_.clear();
      pos_ = 0;
      std::istringstream ws(line);
      std::string w;
      while (ws >> w) words_.push_back(w);
    }
  }
  std::string expect_word(const std::string& what) {
    std::string t;
    if (!next(t)) fail(what, "unexpected end of file, expected " + what);
    return t;
  }
  double expect_number(const std::string& what) {
    const std::string t = expect_word(what);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (*end != '\0' || !std::isfinite(v)) fail(what, "expected a number, found " + quote(t));
    return v;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw InputError(Location{path_, line_, 0}, key, message);
  }

 private:
  std::string path_;
  std::istringstream in_;
  std::vector<std::string> words_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

Eigen::Matrix3d channel_rotation(const std::string& channel, double deg) {
  const double a = deg_to_rad(deg);
  if (channel == "Xrotation")
    return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
  if (channel == "Yrotation")
    return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

PoseTrack load_bvh(const std::string& path, const BvhOptions& options) {
  BvhLexer lex(path);
  std::vector<BvhJoint> joints;
  std::vector<int> stack;
  int channel_count = 0;
  std::string tok = lex.expect_word("HIERARCHY");
  if (tok != "HIERARCHY")
    lex.fail("HIERARCHY", "not a BVH file: expected HIERARCHY, found " + quote(tok));
  int pending = -1;  // joint awaiting its "{"
  bool in_end_site = false;
  while (true) {
    tok = lex.expect_word("MOTION");
    if (tok == "MOTION") break;
    if (tok == "ROOT" || tok == "JOINT") {
      BvhJoint j;
      j.name = lex.expect_word("joint name");
      j.parent = stack.empty() ? -1 : stack.back();
      if (tok == "ROOT" && !joints.empty()) lex.fail("ROOT", "only one ROOT is supported");
      joints.push_back(j);
      pending = static_cast<int>(joints.size()) - 1;
    } else if (tok == "End") {
      lex.expect_word("Site");
      in_end_site = true;
    } else if (tok == "{") {
      if (in_end_site) {
        stack.push_back(-2);
        in_end_site = false;
      } else {
        if (pending < 0) lex.fail("{", "unexpected \"{\"");
        stack.push_back(pending);
        pending = -1;
      }
    } else if (tok == "}") {
      if (stack.empty()) lex.fail("}", "unbalanced \"}\"");
      stack.pop_back();
    } else if (tok == "OFFSET") {
      for (int i = 0; i < 3; ++i) lex.expect_number("OFFSET");
    } else if (tok == "CHANNELS") {
      if (stack.empty() || stack.back() < 0) lex.fail("CHANNELS", "CHANNELS outside a joint");
      const double n = lex.expect_number("CHANNELS");
      if (n < 0 || n > 6 || n != std::floor(n)) lex.fail("CHANNELS", "expected 0..6 channels");
      BvhJoint& j = joints[static_cast<std::size_t>(stack.back())];
      j.first_channel = channel_count;
      for (int i = 0; i < static_cast<int>(n); ++i) {
        const std::string c = lex.expect_word("channel name");
        static const char* kKnown[] = {"Xposition", "Yposition", "Zposition",
                                       "Xrotation", "Yrotation", "Zrotation"};
        if (std::find(std::begin(kKnown), std::end(kKnown), c) == std::end(kKnown)) {
          lex.fail("CHANNELS", "unknown channel " + quote(c));
        }
        j.channels.push_back(c);
      }
      channel_count += static_cast<int>(n);
    } else {
      lex.fail("HIERARCHY", "unexpected " + quote(tok));
    }
  }
  if (!stack.empty()) lex.fail("MOTION", "unbalanced braces before MOTION");
  if (joints.empty()) lex.fail("ROOT", "no joints in the hierarchy");

  auto find_joint = [&](const std::string& name, const std::string& key) {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      if (joints[i].name == name) return static_cast<int>(i);
    }
    std::string have;
    for (const auto& j : joints) have += (have.empty() ? "" : ", ") + j.name;
    throw InputError(Location{path, 0, 0}, key,
                     "no joint named " + quote(name) + " (joints: " + have + ")");
  };
  const int head = find_joint(options.head_joint, "head_joint");
  const int torso =
      options.torso_joint.empty() ? 0 : find_joint(options.torso_joint, "torso_joint");
  std::vector<int> chain;  // head up to, excluding, the torso
  for (int j = head; j != torso; j = joints[static_cast<std::size_t>(j)].parent) {
    if (j < 0) {
      throw InputError(Location{path, 0, 0}, "torso_joint",
                       "joint " + quote(options.head_joint) + " is not below " +
                           quote(joints[static_cast<std::size_t>(torso)].name));
    }
    chain.push_back(j);
  }
  std::reverse(chain.begin(), chain.end());

  if (lex.expect_word("Frames:") != "Frames:") lex.fail("Frames", "expected \"Frames:\"");
  const double frames = lex.expect_number("Frames");
  if (frames < 1 || frames != std::floor(frames))
    lex.fail("Frames", "expected a positive frame count");
  if (lex.expect_word("Frame") != "Frame" || lex.expect_word("Time:") != "Time:") {
    lex.fail("Frame Time", "expected \"Frame Time:\"");
  }
  const double dt = lex.expect_number("Frame Time");
  if (!(dt > 0)) lex.fail("Frame Time", "expected a positive frame time");

  // BVH axes (x left, y up, z forward) into ours (x forward, y left, z up).
  Eigen::Matrix3d c;
  c << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  PoseTrack track;
  std::vector<double> values(static_cast<std::size_t>(channel_count));
  for (int f = 0; f < static_cast<int>(frames); ++f) {
    for (auto& v : values) v = lex.expect_number("frame " + std::to_string(f + 1));
    Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
    for (int j : chain) {
      const BvhJoint& joint = joints[static_cast<std::size_t>(j)];
      for (std::size_t k = 0; k < joint.channels.size(); ++k) {
        if (joint.channels[k].find("rotation") == std::string::npos) continue;
        r = r * channel_rotation(joint.channels[k],
                                 values[static_cast<std::size_t>(joint.first_channel) + k]);
      }
    }
    track.times.push_back(f * dt);
    track.poses.push_back(matrix_to_euler(c * r * c.transpose()));
  }
  return track;
}

// ---------------------------------------------------------------- markers

PoseTrack load_marker_csv(const std::string& path, int reference_frame) {
  const CsvTable table = read_csv_table(path);
  const int t = table.require("time_s");
  check_increasing(table, t);
  std::vector<std::string> names;
  std::map<std::string, std::array<int, 3>> cols;
  for (const auto& h : table.header) {
    if (h.size() > 2 && (ends_with(h, "_x"))) {
      const std::string name = h.substr(0, h.size() - 2);
      names.push_back(name);
      cols[name] = {table.column(name + "_x"), table.require(name + "_y"),
                    table.require(name + "_z")};
    }
  }
  if (names.size() < 3) {
    throw InputError(Location{path, 1, 1}, "",
                     "expected at least 3 markers (NAME_x, NAME_y, NAME_z columns), found " +
                         std::to_string(names.size()));
  }
  if (reference_frame < 0 || static_cast<std::size_t>(reference_frame) >= table.rows.size()) {
    throw InputError(Location{path, 0, 0}, "reference_frame", "reference frame out of range");
  }
  const auto nose = std::find(names.begin(), names.end(), "nose");
  auto frame_matrix = [&](const std::vector<double>& row) {
    Eigen::MatrixX3d m(static_cast<Eigen::Index>(names.size()), 3);
    for (std::size_t i = 0; i < names.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        m(static_cast<Eigen::Index>(i), k) =
            row[static_cast<std::size_t>(cols[names[i]][static_cast<std::size_t>(k)])];
      }
    }
    const Eigen::RowVector3d origin = nose != names.end()
                                          ? Eigen::RowVector3d(m.row(nose - names.begin()))
                                          : Eigen::RowVector3d(m.colwise().mean());
    m.rowwise() -= origin;
    return m;
  };
  const Eigen::MatrixX3d reference =
      frame_matrix(table.rows[static_cast<std::size_t>(reference_frame)]);
  PoseTrack track;
  for (const auto& row : table.rows) {
    track.times.push_back(row[static_cast<std::size_t>(t)]);
    track.poses.push_back(matrix_to_euler(rotation_from_markers(reference, frame_matrix(row))));
  }
  return track;
}

PoseTrack load_pose_file(const std::string& path) {
  if (ends_with(path, ".bvh")) return load_bvh(path);
  if (ends_with(path, ".markers.csv")) return load_marker_csv(path);
  return load_euler_csv(path);
}

}  // namespace animrt::head
