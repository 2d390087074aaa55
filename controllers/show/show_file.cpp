#include "animrt/controllers/show/show_file.hpp"

#include <sndfile.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/controllers/seqnet/output_check.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

// Plausible show sizes (docs/show.md lists them): key times and the
// duration up to 1e6 s (11 days, longer than any show runs unattended);
// a learned show completes at most an hour of frames at 25 per second.
constexpr double kMaxShowS = 1e6;
constexpr double kMinLearnedFrameS = 0.001;
constexpr double kMaxLearnedFrameS = 1.0;
constexpr double kMaxLearnedFrames = 100000.0;

// `learned` is a whole track's interpolation: the model completes the
// track between all its keys at once.
Interpolation parse_interpolation(const YamlNode& node, bool track) {
  const std::string s = node.as_string();
  if (s == "step") return Interpolation::step;
  if (s == "linear") return Interpolation::linear;
  if (s == "cubic") return Interpolation::cubic;
  if (s == "learned" && track) return Interpolation::learned;
  if (s == "learned") node.fail("learned is set for a whole track, not for one key");
  node.fail(std::string(track ? "expected step, linear, cubic or learned"
                              : "expected step, linear or cubic") +
            ", found " + node.describe());
}

// The `learned` section: the model is read now, so a missing, corrupt or
// mismatched model stops the show at load with the show's line.
void load_learned(const YamlNode& root, ShowFile& show, const std::filesystem::path& folder) {
  std::vector<const ShowTrack*> learned;
  for (const ShowTrack& t : show.tracks) {
    if (t.keys.front().interpolation == Interpolation::learned) learned.push_back(&t);
  }
  const auto section = root.find("learned");
  if (!section) {
    if (learned.empty()) return;
    throw InputError(learned.front()->where, "joints." + learned.front()->joint + ".interpolation",
                     "interpolation learned needs a `learned: {model: FILE, frame_s: S}` section "
                     "naming the joint-space model");
  }
  section->allow_only({"model", "frame_s"});
  if (learned.empty()) {
    section->fail("no joint uses interpolation: learned");
  }
  const YamlNode model_node = section->at("model");
  const std::string given = model_node.as_string();
  const std::filesystem::path resolved =
      std::filesystem::path(given).is_absolute() ? std::filesystem::path(given) : folder / given;
  show.has_learned = true;
  show.learned.model_file = resolved.string();
  show.learned.where = section->location();
  const YamlNode frame_node = section->at("frame_s");
  show.learned.frame_s = frame_node.as_positive_double();
  // A model's frame is from 1 ms (a fast capture) to 1 s; every frame of
  // the show is completed and stored at load, so their count is bounded too.
  if (show.learned.frame_s < kMinLearnedFrameS || show.learned.frame_s > kMaxLearnedFrameS) {
    frame_node.fail("expected a number from " + format_number(kMinLearnedFrameS) + " to " +
                    format_number(kMaxLearnedFrameS) + ", found " + frame_node.describe());
  }

  seqnet::ModelFile model;
  try {
    model = seqnet::read_model_file(show.learned.model_file);
  } catch (const InputError& e) {
    model_node.fail("model " + quote_path(show.learned.model_file) + ": " + e.what());
  } catch (const std::exception& e) {
    model_node.fail("cannot read model " + quote_path(show.learned.model_file) + ": " + e.what());
  }
  if (model.shape.kind != seqnet::ModelKind::joints) {
    model_node.fail("model " + quote_path(show.learned.model_file) + " is a " +
                    seqnet::kind_name(model.shape.kind) +
                    " model; a show needs a joint-space model (animrt seq train on joint CSVs)");
  }
  std::vector<std::string> names;
  for (const ShowTrack* t : learned) names.push_back(t->joint);
  try {
    seqnet::check_model_joints(model, show.learned.model_file, names);
  } catch (const InputError& e) {
    model_node.fail(std::string(e.what()) +
                    " (the show's learned tracks must be the model's joints)");
  }
  // A model that computes inf or NaN from its own range would play them
  // (inf clamped to a limit unnoticed): refused here, with the show's line.
  try {
    seqnet::check_model_output(model, show.learned.model_file);
  } catch (const InputError& e) {
    model_node.fail(e.what());
  }
  show.learned.joints = model.joint_names;
  show.learned.model = std::make_shared<const seqnet::ModelFile>(std::move(model));

  // One key frame holds every learned joint: the tracks share their times.
  const ShowTrack& first = *learned.front();
  for (const ShowTrack* t : learned) {
    const std::string key = "joints." + t->joint + ".keys";
    if (t->keys.size() != first.keys.size()) {
      throw InputError(t->where, key,
                       "learned tracks share their key times: " + t->joint + " has " +
                           std::to_string(t->keys.size()) + " keys, " + first.joint + " has " +
                           std::to_string(first.keys.size()));
    }
    for (std::size_t k = 0; k < t->keys.size(); ++k) {
      if (std::abs(t->keys[k].t - first.keys[k].t) > 1e-9) {
        throw InputError(t->keys[k].where, key,
                         "learned tracks share their key times: this key is at " +
                             format_number(t->keys[k].t) + " s, " + first.joint + "'s key " +
                             std::to_string(k + 1) + " at " + format_number(first.keys[k].t) +
                             " s");
      }
    }
  }
  // Every completed frame is stored: a looping show completes its whole
  // duration, another from its first learned key to its last.
  const double span = show.loop ? show.duration_s : first.keys.back().t - first.keys.front().t;
  if (const double frames = span / show.learned.frame_s; frames > kMaxLearnedFrames) {
    frame_node.fail("the learned tracks span " + format_number(span) + " s, " +
                    format_number(std::ceil(frames)) + " frames of " + frame_node.describe() +
                    " s; expected at most " + format_number(kMaxLearnedFrames) +
                    " frames (a longer frame_s, or a shorter show)");
  }
  // Every gap is a whole number of the model's frames.
  const double frame = show.learned.frame_s;
  auto check_gap = [&](double t0, double t1, const ShowKey& key) {
    const double frames = (t1 - t0) / frame;
    if (std::abs(frames - std::round(frames)) > 1e-6 * std::max(1.0, frames)) {
      throw InputError(key.where, "joints." + first.joint + ".keys",
                       "learned keys lie on the model's frames: " + format_number(t0) + " s to " +
                           format_number(t1) + " s is " + format_number(frames) +
                           " frames of frame_s " + format_number(frame) + " s, not a whole number");
    }
    if (std::round(frames) < 2) {
      throw InputError(key.where, "joints." + first.joint + ".keys",
                       "learned keys are at least two frames apart, so the model has a frame "
                       "to fill: " +
                           format_number(t0) + " s to " + format_number(t1) + " s is " +
                           (std::round(frames) == 1.0 ? "one frame" : "no frame") + " of frame_s " +
                           format_number(frame) + " s");
    }
  };
  for (std::size_t k = 0; k + 1 < first.keys.size(); ++k) {
    check_gap(first.keys[k].t, first.keys[k + 1].t, first.keys[k + 1]);
  }
  if (show.loop && first.keys.size() > 1) {
    check_gap(first.keys.back().t, first.keys.front().t + show.duration_s, first.keys.front());
  }
}

}  // namespace

ShowFile load_show_file(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  root.allow_only({"name", "loop", "duration_s", "audio", "joints", "learned"});
  ShowFile show;
  show.file = path;
  show.name = root.get_string("name", "");
  show.loop = root.get_bool("loop", false);
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(path).parent_path();

  const YamlNode joints = root.at("joints");
  const auto entries = joints.entries();
  if (entries.empty()) joints.fail("expected at least one joint, found an empty map");
  double last = 0.0;
  for (const auto& [name, node] : entries) {
    node.allow_only({"unit", "interpolation", "keys"});
    ShowTrack track;
    track.joint = name;
    track.where = node.location();
    if (auto u = node.find("unit")) {
      const std::string unit = u->as_string();
      if (unit == "deg") {
        track.unit = ShowUnit::deg;
      } else if (unit == "m") {
        track.unit = ShowUnit::m;
      } else {
        u->fail("expected deg (revolute joint) or m (prismatic joint), found " + u->describe());
      }
      track.unit_where = u->location();
    }
    Interpolation fallback = Interpolation::cubic;
    if (auto i = node.find("interpolation")) fallback = parse_interpolation(*i, true);
    const YamlNode keys = node.at("keys");
    const auto items = keys.items();
    if (items.empty()) keys.fail("expected at least one key, found an empty list");
    for (const YamlNode& item : items) {
      ShowKey key;
      key.interpolation = fallback;
      key.where = item.location();
      // YamlNode must not be assigned (yaml-cpp nodes assign through), so the
      // time and value nodes are built once.
      std::optional<YamlNode> t_node, v_node;
      if (item.is_sequence()) {
        const auto pair = item.items();
        if (pair.size() != 2)
          item.fail("expected [time_s, value], found a list of " + std::to_string(pair.size()));
        t_node.emplace(pair[0]);
        v_node.emplace(pair[1]);
      } else if (item.is_map()) {
        item.allow_only({"t", "value", "interpolation"});
        t_node.emplace(item.at("t"));
        v_node.emplace(item.at("value"));
        if (auto i = item.find("interpolation")) {
          if (fallback == Interpolation::learned) {
            i->fail("a learned track's keys take no interpolation of their own");
          }
          key.interpolation = parse_interpolation(*i, false);
        }
      } else {
        item.fail("expected [time_s, value] or {t, value, interpolation}, found " +
                  item.describe());
      }
      key.t = t_node->as_double_in(0.0, kMaxShowS);
      key.value = v_node->as_double();
      if (!track.keys.empty() && !(key.t > track.keys.back().t)) {
        t_node->fail("expected a time after the previous key's " +
                     format_number(track.keys.back().t) + " s, found " + t_node->describe());
      }
      track.keys.push_back(key);
    }
    last = std::max(last, track.keys.back().t);
    show.tracks.push_back(std::move(track));
  }
  show.duration_s = last;
  if (auto d = root.find("duration_s")) {
    show.duration_s = d->as_positive_double();
    if (show.duration_s > kMaxShowS) {
      d->fail("expected at most " + format_number(kMaxShowS) + " s, found " + d->describe());
    }
    if (show.duration_s < last) {
      d->fail("expected at least the last key's time (" + format_number(last) + " s), found " +
              d->describe());
    }
  }
  if (show.loop && !(show.duration_s > 0.0))
    root.at("loop").fail("a looping show needs a duration > 0");
  // Looping, a key at duration_s and one at 0 are the same instant of the
  // next pass: with other values the joint would jump there every pass.
  for (const ShowTrack& track : show.tracks) {
    if (!show.loop || track.keys.size() < 2) continue;
    const ShowKey& first = track.keys.front();
    const ShowKey& end = track.keys.back();
    if (first.t == 0.0 && end.t == show.duration_s && end.value != first.value) {
      throw InputError(end.where, "joints." + track.joint + ".keys",
                       "the key at " + format_number(end.t) + " s (" + format_number(end.value) +
                           ") and the first at 0 s (" + format_number(first.value) +
                           ") are one instant of the loop: the joint would jump there each "
                           "pass; give them one value, or end the keys before duration_s");
    }
  }

  load_learned(root, show, folder);

  if (auto a = root.find("audio")) {
    a->allow_only({"file", "offset_s"});
    const YamlNode file = a->at("file");
    const std::string given = file.as_string();
    const fs::path resolved = fs::path(given).is_absolute() ? fs::path(given) : folder / given;
    show.has_audio = true;
    show.audio.file = resolved.string();
    if (auto o = a->find("offset_s")) show.audio.offset_s = o->as_double_in(-1e6, 1e6);
    std::error_code ec;
    if (!fs::exists(resolved, ec)) {
      file.fail("audio file not found: " + quote_path(given) +
                " (resolved against the show file's folder to " + quote_path(show.audio.file) +
                ")");
    }
    if (const std::string problem = input_file_problem(show.audio.file, kMaxMediaFileBytes);
        !problem.empty()) {
      file.fail("audio file " + quote_path(show.audio.file) + " " + problem);
    }
    if (const std::string cut = head::wav_truncation(show.audio.file); !cut.empty())
      file.fail("audio file " + quote_path(show.audio.file) + ": " + cut);
    SF_INFO info{};
    SNDFILE* sf = sf_open(show.audio.file.c_str(), SFM_READ, &info);
    if (sf == nullptr) {
      file.fail("cannot open audio file " + quote_path(show.audio.file) + ": " +
                sf_strerror(nullptr));
    }
    sf_close(sf);
    if (info.frames <= 0 || info.samplerate <= 0) {
      file.fail("audio file " + quote_path(show.audio.file) + " holds no sound");
    }
    if (info.samplerate < kMinShowAudioRate || info.samplerate > kMaxShowAudioRate) {
      file.fail("audio file " + quote_path(show.audio.file) + " declares a sample rate of " +
                std::to_string(info.samplerate) + " Hz, expected " +
                std::to_string(kMinShowAudioRate) + ".." + std::to_string(kMaxShowAudioRate) +
                " Hz");
    }
    // The run's loader refuses a NaN or infinite sample; validate must too.
    if (const std::string bad = head::audio_nonfinite_sample(show.audio.file); !bad.empty())
      file.fail("audio file " + quote_path(show.audio.file) + ": " + bad);
    show.audio.sample_rate = info.samplerate;
    show.audio.channels = info.channels;
    show.audio.length_s = static_cast<double>(info.frames) / info.samplerate;
  }
  return show;
}

}  // namespace animrt
