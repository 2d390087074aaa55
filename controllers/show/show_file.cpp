#include "animrt/controllers/show/show_file.hpp"

#include <sndfile.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

Interpolation parse_interpolation(const YamlNode& node) {
  const std::string s = node.as_string();
  if (s == "step") return Interpolation::step;
  if (s == "linear") return Interpolation::linear;
  if (s == "cubic") return Interpolation::cubic;
  node.fail("expected step, linear or cubic, found " + node.describe());
}

}  // namespace

ShowFile load_show_file(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  root.allow_only({"name", "loop", "duration_s", "audio", "joints"});
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
    if (auto i = node.find("interpolation")) fallback = parse_interpolation(*i);
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
        if (auto i = item.find("interpolation")) key.interpolation = parse_interpolation(*i);
      } else {
        item.fail("expected [time_s, value] or {t, value, interpolation}, found " +
                  item.describe());
      }
      key.t = t_node->as_double_in(0.0, 1e6);
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
    if (show.duration_s < last) {
      d->fail("expected at least the last key's time (" + format_number(last) + " s), found " +
              d->describe());
    }
  }
  if (show.loop && !(show.duration_s > 0.0))
    root.at("loop").fail("a looping show needs a duration > 0");

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
      file.fail("audio file not found: \"" + given +
                "\" (resolved against the show file's folder to \"" + show.audio.file + "\")");
    }
    if (const std::string problem = input_file_problem(show.audio.file, kMaxMediaFileBytes);
        !problem.empty()) {
      file.fail("audio file \"" + show.audio.file + "\" " + problem);
    }
    SF_INFO info{};
    SNDFILE* sf = sf_open(show.audio.file.c_str(), SFM_READ, &info);
    if (sf == nullptr) {
      file.fail("cannot open audio file \"" + show.audio.file + "\": " + sf_strerror(nullptr));
    }
    sf_close(sf);
    if (info.frames <= 0 || info.samplerate <= 0) {
      file.fail("audio file \"" + show.audio.file + "\" holds no sound");
    }
    if (info.samplerate < kMinShowAudioRate || info.samplerate > kMaxShowAudioRate) {
      file.fail("audio file \"" + show.audio.file + "\" declares a sample rate of " +
                std::to_string(info.samplerate) + " Hz, expected " +
                std::to_string(kMinShowAudioRate) + ".." + std::to_string(kMaxShowAudioRate) +
                " Hz");
    }
    show.audio.sample_rate = info.samplerate;
    show.audio.channels = info.channels;
    show.audio.length_s = static_cast<double>(info.frames) / info.samplerate;
  }
  return show;
}

}  // namespace animrt
