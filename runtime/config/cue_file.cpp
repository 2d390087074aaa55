#include "animrt/runtime/cue_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "animrt/controllers/cues/pose_source.hpp"
#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/head/head_source.hpp"
#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/controllers/seqnet/output_check.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "animrt/runtime/ltc_chase.hpp"
#include "animrt/runtime/robot_loader.hpp"

namespace animrt {
namespace {

// What a cue says while it is read, before the cues it names are known.
struct CueDraft {
  std::optional<YamlNode> then_node;
  std::optional<YamlNode> loop_node;
  std::optional<YamlNode> node;
};

std::string cue_names(const std::vector<Cue>& cues) {
  std::string names;
  for (const Cue& cue : cues) names += (names.empty() ? "" : ", ") + cue.name;
  return names;
}

std::string resolve(const YamlNode& file, const std::string& cue_path) {
  const std::string given = file.as_string();
  if (given.empty()) file.fail("expected a file path, found \"\"");
  namespace fs = std::filesystem;
  const fs::path path =
      fs::path(given).is_absolute() ? fs::path(given) : fs::path(cue_path).parent_path() / given;
  const std::string problem = input_file_problem(path.string());
  if (problem == kFileMissing) file.fail("file not found: " + quote_path(path.string()));
  if (!problem.empty()) file.fail(quote_path(path.string()) + " " + problem);
  return path.string();
}

// A joint position as a cue file writes it (degrees; metres for a prismatic
// joint), in SI and within the joint's limits. The limits are kept in SI
// and 60 deg reads back as 59.99999999999999: a value at a limit as the
// robot file writes it passes by a rounding margin and is held to it.
double position_within_limits(const YamlNode& value, const JointSpec& joint) {
  const bool metres = joint.type == JointType::prismatic;
  const auto as_written = [metres](double si) { return metres ? si : rad_to_deg(si); };
  const double lo = as_written(joint.limits.min_position);
  const double hi = as_written(joint.limits.max_position);
  const double margin = 1e-9 * std::max({1.0, std::abs(lo), std::abs(hi)});
  const double given = value.as_double_in(lo - margin, hi + margin);
  return std::clamp(metres ? given : deg_to_rad(given), joint.limits.min_position,
                    joint.limits.max_position);
}

std::unique_ptr<MotionSource> make_pose(const YamlNode& node, const RobotConfig& robot) {
  std::vector<std::pair<int, double>> pose;
  for (const auto& [name, value] : node.entries()) {
    int index = -1;
    for (std::size_t j = 0; j < robot.joints.size(); ++j) {
      if (robot.joints[j].name == name) index = static_cast<int>(j);
    }
    if (index < 0) value.fail("no joint " + quote(name) + " in robot " + robot.name);
    pose.emplace_back(index,
                      position_within_limits(value, robot.joints[static_cast<std::size_t>(index)]));
  }
  if (pose.empty()) node.fail("expected joint: degrees pairs, found none");
  return make_pose_source(std::move(pose));
}

// A motion, its warnings kept with the cue file's line and key.
std::unique_ptr<MotionSource> load_warned(const MotionConfig& motion, const RobotConfig& robot,
                                          std::vector<std::string>& warnings) {
  std::vector<std::string> own;
  auto source = load_motion_source(motion, robot, own);
  for (const std::string& w : own)
    warnings.push_back(motion.where.file + ":" + std::to_string(motion.where.line) + ": " +
                       motion.key + ": " + w);
  return source;
}

std::unique_ptr<MotionSource> load_file_motion(const YamlNode& file, const std::string& type,
                                               const std::string& cue_path,
                                               const RobotConfig& robot,
                                               std::vector<std::string>& warnings) {
  MotionConfig motion;
  motion.type = type;
  motion.file = resolve(file, cue_path);
  motion.where = file.location();
  motion.key = file.path();
  return load_warned(motion, robot, warnings);
}

// Speech-driven head motion (the keys of a robot file's head motion, paths
// relative to the cue file). A sound file is analysed at load, so the cue
// plays it from its start each time it is asked for; live sound (capture,
// or live: true) is heard from the run's start, and the cue joins it. Plays
// for the sound's length when it does not repeat, else until the next cue.
std::unique_ptr<MotionSource> make_head(const YamlNode& node, const std::string& cue_path,
                                        const RobotConfig& robot, double& duration_s,
                                        std::vector<std::string>& warnings) {
  auto config = std::make_shared<head::HeadMotionConfig>(head::parse_head_motion(node, cue_path));
  const bool file = config->capture.empty() && !config->live;
  config->precomputed = file;
  if (file && !config->repeat) duration_s = head::load_head_audio(*config).duration_s();
  MotionConfig motion;
  motion.type = "head";
  motion.head = config;
  motion.where = node.location();
  motion.key = node.path();
  return load_warned(motion, robot, warnings);
}

// One step: a gait, a show, a pose, a head, or several of them layered in
// that order (later ones win on the joints they drive), and how long it
// plays: a show that does not loop for its length, a head for its sound's,
// everything else until the next cue.
CueStep make_step(const YamlNode& node, const std::string& cue_path, const RobotConfig& robot,
                  std::vector<std::string>& warnings) {
  node.allow_only({"gait", "show", "pose", "head", "duration_s"});
  if (!node.has("show") && !node.has("gait") && !node.has("pose") && !node.has("head")) {
    node.fail("expected a gait, a show, a pose or a head (or several, layered), found none");
  }
  CueStep step;
  std::vector<std::unique_ptr<MotionSource>> layers;
  if (auto gait = node.find("gait"))
    layers.push_back(load_file_motion(*gait, "gait", cue_path, robot, warnings));
  if (auto show = node.find("show")) {
    layers.push_back(load_file_motion(*show, "show", cue_path, robot, warnings));
    const ShowFile file = load_show_file(resolve(*show, cue_path));
    if (!file.loop) step.duration_s = file.duration_s;
    if (file.has_audio) step.show_file = file.file;
  }
  if (auto head = node.find("head")) {
    double length = kForever;
    layers.push_back(make_head(*head, cue_path, robot, length, warnings));
    if (length != kForever)  // the speech ends the step (or the longer of it and a show)
      step.duration_s = step.duration_s == kForever ? length : std::max(step.duration_s, length);
  }
  if (auto pose = node.find("pose")) layers.push_back(make_pose(*pose, robot));
  step.source =
      layers.size() == 1 ? std::move(layers.front()) : make_layered_source(std::move(layers));
  if (auto d = node.find("duration_s")) {
    // At most what a show may last (11 days: longer than any cue plays
    // unattended); a longer one is a typo, as good as never ending.
    constexpr double kMaxStepS = 1e6;
    step.duration_s = d->as_positive_double();
    if (step.duration_s > kMaxStepS) d->fail("expected at most 1000000 s, found " + d->describe());
  }
  return step;
}

// A transition as written, and where, so that a cue it does not fit can
// be refused with its line.
struct TransitionDraft {
  CueTransition transition;
  std::optional<YamlNode> node;
};

// The model files the transitions name, each read and checked once.
using ModelCache = std::map<std::string, std::shared_ptr<const seqnet::ModelFile>>;

// `transition: {interpolation: crossfade}` or `{interpolation: learned,
// model: FILE, frame_s: S}`: the model is read and checked against the
// robot now, so a bad one stops the cue file at load with its line.
TransitionDraft read_transition(const YamlNode& node, const std::string& cue_path,
                                const RobotConfig& robot, ModelCache& models,
                                std::vector<std::string>& warnings) {
  node.allow_only({"interpolation", "model", "frame_s"});
  TransitionDraft draft;
  draft.node = node;
  const YamlNode kind = node.at("interpolation");
  const std::string how = kind.as_string();
  if (how != "crossfade" && how != "learned") {
    kind.fail("expected crossfade or learned, found " + quote(how));
  }
  if (how == "crossfade") {
    for (const char* key : {"model", "frame_s"}) {
      if (auto extra = node.find(key))
        extra->fail("only a learned transition takes a " + std::string(key));
    }
    return draft;
  }
  CueTransition& tr = draft.transition;
  const YamlNode frame = node.at("frame_s");
  tr.frame_s = frame.as_double_in(0.001, 1.0);
  const YamlNode model_node = node.at("model");
  tr.model_file = resolve(model_node, cue_path);
  if (auto known = models.find(tr.model_file); known != models.end()) {
    tr.model = known->second;
  } else {
    seqnet::ModelFile model;
    try {
      model = seqnet::read_model_file(tr.model_file);
    } catch (const InputError& e) {
      model_node.fail("model " + quote_path(tr.model_file) + ": " + e.what());
    } catch (const std::exception& e) {
      model_node.fail("cannot read model " + quote_path(tr.model_file) + ": " + e.what());
    }
    if (model.shape.kind != seqnet::ModelKind::joints) {
      model_node.fail("model " + quote_path(tr.model_file) + " is a " +
                      seqnet::kind_name(model.shape.kind) +
                      " model; a transition needs a joint-space model (animrt seq train on joint "
                      "CSVs)");
    }
    try {
      seqnet::check_model_output(model, tr.model_file);
      seqnet::SeqNetInference net(model, tr.model_file);  // every parameter of its shape
    } catch (const std::exception& e) {
      model_node.fail(e.what());
    }
    const std::string w = seqnet::interpolation_warning(model, tr.model_file);
    if (!w.empty()) {
      const Location at = model_node.location();
      warnings.push_back(at.file + ":" + std::to_string(at.line) + ": " + model_node.path() + ": " +
                         w.substr(w.find(' ') + 1));  // without "warning: "
    }
    tr.model = std::make_shared<const seqnet::ModelFile>(std::move(model));
    models.emplace(tr.model_file, tr.model);
  }
  for (const std::string& name : tr.model->joint_names) {
    int index = -1;
    for (std::size_t j = 0; j < robot.joints.size(); ++j) {
      if (robot.joints[j].name == name) index = static_cast<int>(j);
    }
    if (index < 0) {
      std::string names;
      for (const JointSpec& j : robot.joints) names += (names.empty() ? "" : ", ") + j.name;
      model_node.fail("model " + quote_path(tr.model_file) + " moves joint " + quote(name) +
                      ", which robot " + robot.name + " does not have (its joints: " + names + ")");
    }
    tr.joints.push_back(index);
  }
  return draft;
}

Cue make_cue(const std::string& name, const YamlNode& node, double crossfade,
             const TransitionDraft& default_transition, const std::string& cue_path,
             const RobotConfig& robot, ModelCache& models, std::vector<std::string>& warnings) {
  node.allow_only({"play", "crossfade_s", "transition", "loop", "then", "dmx", "timecode", "midi"});
  Cue cue;
  cue.name = name;
  cue.crossfade_s = crossfade;
  if (auto c = node.find("crossfade_s")) cue.crossfade_s = c->as_double_in(0.0, 60.0);
  const TransitionDraft transition =
      node.has("transition")
          ? read_transition(node.at("transition"), cue_path, robot, models, warnings)
          : default_transition;
  cue.transition = transition.transition;
  if (cue.transition.learned() && cue.crossfade_s < 2.0 * cue.transition.frame_s) {
    const YamlNode& at = node.has("crossfade_s") ? node.at("crossfade_s") : *transition.node;
    at.fail("cue " + cue.name + ": a learned transition needs a crossfade of at least two of the " +
            "model's frames (" + format_number(2.0 * cue.transition.frame_s) + " s), found " +
            format_number(cue.crossfade_s) + " s");
  }
  const YamlNode play = node.at("play");
  std::vector<YamlNode> steps = play.is_sequence() ? play.items() : std::vector<YamlNode>{play};
  if (steps.empty()) play.fail("expected at least one step, found an empty list");
  for (const YamlNode& step : steps)
    cue.steps.push_back(make_step(step, cue_path, robot, warnings));
  for (std::size_t s = 0; s + 1 < cue.steps.size(); ++s) {
    if (cue.steps[s].duration_s == kForever) {
      steps[s].fail(
          "this step never ends (a gait, a pose or a looping show), so the steps after "
          "it never play; give it duration_s");
    }
  }
  cue.loop = node.get_bool("loop", false);
  return cue;
}

// A cue hands over to another when it ends (`then`, or the idle cue); cues
// that hand over to one another in a ring that never reaches the idle cue
// would never stop playing on their own.
void check_handovers(const std::vector<Cue>& cues, int idle, const std::vector<CueDraft>& drafts) {
  for (std::size_t first = 0; first < cues.size(); ++first) {
    std::vector<bool> seen(cues.size(), false);
    std::string path = cues[first].name;
    int at = static_cast<int>(first);
    while (at != idle && cues[static_cast<std::size_t>(at)].then >= 0) {
      seen[static_cast<std::size_t>(at)] = true;
      at = cues[static_cast<std::size_t>(at)].then;
      path += " -> " + cues[static_cast<std::size_t>(at)].name;
      if (at != idle && seen[static_cast<std::size_t>(at)]) {
        drafts[first].then_node->fail("the cues hand over in a loop without an exit (" + path +
                                      "): one of them must end at the idle cue " +
                                      quote(cues[static_cast<std::size_t>(idle)].name));
      }
    }
  }
}

void link_cue(std::vector<Cue>& cues, std::size_t c, int idle, const CueDraft& draft) {
  Cue& cue = cues[c];
  const bool forever = cue.steps.back().duration_s == kForever;
  if (draft.then_node) {
    const YamlNode& then = *draft.then_node;
    if (static_cast<int>(c) == idle) then.fail("the idle cue repeats; it hands over to no cue");
    if (cue.loop) then.fail("a looping cue never ends, so `then` never comes; drop one");
    if (forever) then.fail("the cue's last step never ends, so `then` never comes");
    cue.then = find_cue(cues, then.as_string());
    if (cue.then < 0) {
      then.fail("no cue named " + quote(then.as_string()) + " (the cues: " + cue_names(cues) + ")");
    }
  }
  if (cue.loop && forever) {
    draft.loop_node->fail("the cue's last step never ends, so it never loops; drop loop");
  }
}

// A cue's MIDI trigger: {note: N} or {program: N}, and an optional channel.
void read_midi_binding(const YamlNode& node, LoadedCues& loaded) {
  node.allow_only({"note", "program", "channel"});
  if (node.has("note") == node.has("program")) node.fail("expected a note or a program, not both");
  MidiBinding binding;
  binding.cue = static_cast<int>(loaded.cues.size() - 1);
  binding.program = node.has("program");
  const YamlNode number = node.at(binding.program ? "program" : "note");
  binding.number = static_cast<int>(number.as_int_in(0, 127));
  if (auto channel = node.find("channel"))
    binding.channel = static_cast<int>(channel->as_int_in(1, 16));
  for (const MidiBinding& other : loaded.midi) {
    if (other.program == binding.program && other.number == binding.number &&
        (other.channel == 0 || binding.channel == 0 || other.channel == binding.channel)) {
      number.fail("cue " + loaded.cues[static_cast<std::size_t>(other.cue)].name +
                  " answers this MIDI message too");
    }
  }
  loaded.midi.push_back(binding);
}

// A joint's DMX channels: `channel` (coarse), `fine` (optional) and the
// `range` (degrees, or metres) that level 0 and full map to.
DmxJoint make_dmx_joint(const std::string& name, const YamlNode& node, const RobotConfig& robot,
                        std::vector<bool>& used) {
  node.allow_only({"channel", "fine", "range"});
  DmxJoint dmx;
  dmx.joint = -1;
  for (std::size_t j = 0; j < robot.joints.size(); ++j) {
    if (robot.joints[j].name == name) dmx.joint = static_cast<int>(j);
  }
  if (dmx.joint < 0) node.fail("no joint " + quote(name) + " in robot " + robot.name);
  auto channel = [&used](const YamlNode& at) {
    const int c = static_cast<int>(at.as_int_in(1, 512));
    if (used[static_cast<std::size_t>(c)])
      at.fail("channel " + std::to_string(c) + " is used twice");
    used[static_cast<std::size_t>(c)] = true;
    return c;
  };
  dmx.coarse = channel(node.at("channel"));
  if (auto fine = node.find("fine")) dmx.fine = channel(*fine);
  const JointSpec& joint = robot.joints[static_cast<std::size_t>(dmx.joint)];
  dmx.min = joint.limits.min_position;
  dmx.max = joint.limits.max_position;
  if (auto range = node.find("range")) {
    const std::vector<YamlNode> ends = range->items();
    if (!range->is_sequence() || ends.size() != 2) {
      range->fail("expected [at level 0, at full], found " + range->describe());
    }
    dmx.min = position_within_limits(ends[0], joint);
    dmx.max = position_within_limits(ends[1], joint);
    if (dmx.min == dmx.max) {
      range->fail(
          "both ends are one position, so the fader would not move the joint; expected "
          "[at level 0, at full]");
    }
  }
  return dmx;
}

// `artnet:` or `sacn:`: the universe, the cue channel, joints.
DmxSection make_dmx_section(const YamlNode& node, int lowest, int highest,
                            const std::vector<int>& dmx_values, const RobotConfig& robot) {
  node.allow_only({"universe", "channel", "joints", "hold_s"});
  DmxSection section;
  section.present = true;
  section.universe = static_cast<int>(node.at("universe").as_int_in(lowest, highest));
  std::vector<bool> used(513, false);
  if (auto channel = node.find("channel")) {
    section.channel = static_cast<int>(channel->as_int_in(1, 512));
    used[static_cast<std::size_t>(section.channel)] = true;
    bool any = false;
    for (int value : dmx_values) any = any || value != 0;
    if (!any) channel->fail("no cue has a dmx value, so this channel would ask for none");
  }
  if (auto joints = node.find("joints")) {
    if (!joints->is_map()) joints->fail("expected a map of joints, found " + joints->describe());
    for (const auto& [name, entry] : joints->entries()) {
      section.joints.push_back(make_dmx_joint(name, entry, robot, used));
    }
  }
  if (section.channel == 0 && section.joints.empty()) {
    node.fail("expected a channel that selects cues, or joints it drives, found neither");
  }
  if (auto hold = node.find("hold_s")) section.hold_s = hold->as_double_in(0.0, 3600.0);
  return section;
}

}  // namespace

int find_cue(const std::vector<Cue>& cues, const std::string& name) {
  for (std::size_t c = 0; c < cues.size(); ++c) {
    if (cues[c].name == name) return static_cast<int>(c);
  }
  return -1;
}

LoadedCues load_cues(const std::string& path, const RobotConfig& robot) {
  const YamlNode root = YamlNode::load_file(path);
  LoadedCues loaded;
  root.allow_only({"idle", "crossfade_s", "transition", "cues", "artnet", "sacn", "ltc"});
  if (auto ltc = root.find("ltc")) {
    ltc->allow_only({"fps", "freewheel_s"});
    loaded.ltc = true;
    if (auto fps = ltc->find("fps")) {
      loaded.ltc_fps = fps->as_double();
      if (loaded.ltc_fps != 24.0 && loaded.ltc_fps != 25.0 && loaded.ltc_fps != 29.97 &&
          loaded.ltc_fps != 30.0) {
        fps->fail("expected 24, 25, 29.97 or 30 frames per second, found " + fps->as_string());
      }
    }
    if (auto f = ltc->find("freewheel_s")) loaded.ltc_freewheel_s = f->as_double_in(0.0, 60.0);
  }
  const double crossfade =
      root.has("crossfade_s") ? root.at("crossfade_s").as_double_in(0.0, 60.0) : 1.0;
  ModelCache models;
  TransitionDraft default_transition;
  if (auto t = root.find("transition"))
    default_transition = read_transition(*t, path, robot, models, loaded.warnings);
  std::vector<CueDraft> drafts;
  const YamlNode list = root.at("cues");
  if (!list.is_map()) list.fail("expected a map of cue names to cues, found " + list.describe());
  for (const auto& [name, node] : list.entries()) {
    const bool plain = !name.empty() && name.find_first_not_of(
                                            "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                            "0123456789_-") == std::string::npos;
    if (!plain) node.fail("a cue's name is letters, digits, _ and - (it is an OSC address)");
    loaded.cues.push_back(
        make_cue(name, node, crossfade, default_transition, path, robot, models, loaded.warnings));
    drafts.push_back({node.find("then"), node.find("loop"), node});
    const auto dmx = node.find("dmx");
    loaded.dmx_values.push_back(dmx ? static_cast<int>(dmx->as_int_in(1, 255)) : 0);
    if (auto tc = node.find("timecode")) {
      const auto start = parse_timecode(tc->as_string(), loaded.ltc_fps);
      if (!start) {
        tc->fail("expected a timecode HH:MM:SS:FF (frames below the ltc: fps), found " +
                 quote(tc->as_string()));
      }
      if (!loaded.ltc) tc->fail("a timecode start needs an `ltc:` section (its frame rate)");
      // One frame starts one cue, as one DMX value or MIDI message asks for one.
      for (const TimecodeCue& other : loaded.timecode_cues) {
        if (std::abs(other.start_s - *start) < 0.5 / loaded.ltc_fps) {
          tc->fail("cue " + loaded.cues[static_cast<std::size_t>(other.cue)].name +
                   " starts at this timecode too");
        }
      }
      loaded.timecode_cues.push_back({*start, static_cast<int>(loaded.cues.size() - 1)});
    }
    if (auto midi = node.find("midi")) read_midi_binding(*midi, loaded);
  }
  if (loaded.cues.empty()) list.fail("expected at least one cue, found none");
  const YamlNode idle = root.at("idle");
  loaded.idle = find_cue(loaded.cues, idle.as_string());
  if (loaded.idle < 0) {
    idle.fail("no cue named " + quote(idle.as_string()) + " (the cues: " + cue_names(loaded.cues) +
              ")");
  }
  for (std::size_t c = 0; c < loaded.cues.size(); ++c) {
    link_cue(loaded.cues, c, loaded.idle, drafts[c]);
  }
  check_handovers(loaded.cues, loaded.idle, drafts);
  for (std::size_t a = 0; a < loaded.dmx_values.size(); ++a) {
    for (std::size_t b = 0; b < a; ++b) {
      if (loaded.dmx_values[a] != 0 && loaded.dmx_values[a] == loaded.dmx_values[b]) {
        drafts[a].node->at("dmx").fail("cue " + loaded.cues[b].name + " has this DMX value too");
      }
    }
  }
  if (auto artnet = root.find("artnet")) {
    loaded.artnet = make_dmx_section(*artnet, 0, 32767, loaded.dmx_values, robot);
    loaded.artnet_universe = loaded.artnet.universe;
    loaded.artnet_channel = loaded.artnet.channel;
  }
  if (auto sacn = root.find("sacn")) {
    loaded.sacn = make_dmx_section(*sacn, 1, 63999, loaded.dmx_values, robot);
  }
  return loaded;
}

}  // namespace animrt
