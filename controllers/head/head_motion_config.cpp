// The head motion section of a robot file.

#include <filesystem>

#include "animrt/controllers/head/head_source.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::head {
namespace {

std::string resolve_file(const YamlNode& node, const std::string& robot_path) {
  namespace fs = std::filesystem;
  const std::string given = node.as_string();
  if (given.empty()) node.fail("expected a file path, found \"\"");
  const fs::path p =
      fs::path(given).is_absolute() ? fs::path(given) : fs::path(robot_path).parent_path() / given;
  const std::string problem = input_file_problem(p.string(), kMaxMediaFileBytes);
  if (problem == kFileMissing)
    node.fail("file not found: " + quote_path(given) + " (resolved to " + quote_path(p.string()) +
              ")");
  if (!problem.empty()) node.fail(quote_path(p.string()) + " " + problem);
  return p.string();
}

HeadAxisMap parse_axis(const YamlNode& n) {
  n.allow_only({"joint", "sign", "scale", "offset_deg"});
  HeadAxisMap a;
  const YamlNode joint = n.at("joint");
  a.where = joint.location();
  a.key = joint.path();
  a.joint = joint.as_string();
  if (auto s = n.find("sign")) {
    a.sign = s->as_double();
    if (a.sign != 1.0 && a.sign != -1.0) s->fail("expected 1 or -1, found " + s->describe());
  }
  if (auto s = n.find("scale")) a.scale = s->as_double_in(0.0, 10.0);
  if (auto s = n.find("offset_deg")) a.offset_deg = s->as_double_in(-180.0, 180.0);
  return a;
}

}  // namespace

HeadMotionConfig parse_head_motion(const YamlNode& node, const std::string& robot_path) {
  node.allow_only({"type", "model", "audio", "capture", "live", "playback", "repeat", "pause_s",
                   "audio_device", "decoder_lag_s", "max_gap_s", "smoothing", "block_s",
                   "noise_deg", "axes", "jaw"});
  HeadMotionConfig c;
  c.where = node.location();
  c.model = resolve_file(node.at("model"), robot_path);
  const auto audio = node.find("audio");
  const auto capture = node.find("capture");
  if (audio && capture)
    capture->fail("give either audio (a file) or capture (a live ALSA device), not both");
  if (!audio && !capture)
    node.fail("missing key \"audio\" (a WAV file) or \"capture\" (an ALSA device)");
  if (audio) {
    c.audio = resolve_file(*audio, robot_path);
    c.audio_where = audio->location();
    c.audio_key = audio->path();
  }
  if (capture) {
    c.capture = capture->as_string();
    if (c.capture.empty()) capture->fail("expected an ALSA device name, found \"\"");
  }
  if (auto l = node.find("live")) {
    c.live = l->as_bool();
    if (capture) l->fail("live applies to an audio file (capture is always live)");
  }
  if (auto p = node.find("playback")) {
    const std::string v = p->as_string();
    if (v != "realtime" && v != "precomputed")
      p->fail("expected realtime or precomputed, found " + p->describe());
    c.precomputed = v == "precomputed";
    if (c.precomputed && (capture || c.live)) p->fail("live input cannot be precomputed");
  }
  c.repeat = node.get_bool("repeat", true);
  if (auto p = node.find("pause_s")) c.pause_s = p->as_double_in(0.0, 60.0);
  c.audio_device = node.get_string("audio_device", "none");
  if (auto p = node.find("decoder_lag_s")) c.decoder_lag_s = p->as_double_in(0.0, 5.0);
  if (auto p = node.find("max_gap_s")) c.max_gap_s = p->as_double_in(0.0, 5.0);
  if (auto p = node.find("smoothing")) {
    const std::string v = p->as_string();
    if (v != "squad" && v != "causal") p->fail("expected squad or causal, found " + p->describe());
    c.causal = v == "causal";
  }
  if (auto p = node.find("block_s")) c.block_s = p->as_double_in(0.001, 0.5);
  if (auto p = node.find("noise_deg")) c.noise_deg = p->as_double_in(0.0, 10.0);
  const YamlNode axes = node.at("axes");
  axes.allow_only({"yaw", "pitch", "roll"});
  if (auto a = axes.find("yaw")) c.yaw = parse_axis(*a);
  if (auto a = axes.find("pitch")) c.pitch = parse_axis(*a);
  if (auto a = axes.find("roll")) c.roll = parse_axis(*a);
  if (auto j = node.find("jaw")) {
    j->allow_only({"joint", "closed_deg", "open_deg", "energy_floor", "energy_full", "window_s"});
    const YamlNode joint = j->at("joint");
    c.jaw.where = joint.location();
    c.jaw.key = joint.path();
    c.jaw.joint = joint.as_string();
    if (auto d = j->find("closed_deg")) c.jaw.closed_deg = d->as_double_in(-360.0, 360.0);
    if (auto d = j->find("open_deg")) c.jaw.open_deg = d->as_double_in(-360.0, 360.0);
    if (auto e = j->find("energy_floor")) c.jaw.energy_floor = e->as_double_in(0.0, 1.0);
    if (auto e = j->find("energy_full")) {
      c.jaw.energy_full = e->as_double_in(0.0, 1.0);
      if (c.jaw.energy_full <= c.jaw.energy_floor) e->fail("must be above energy_floor");
    }
    if (auto w = j->find("window_s")) c.jaw.window_s = w->as_double_in(0.001, 0.2);
  }
  return c;
}

}  // namespace animrt::head
