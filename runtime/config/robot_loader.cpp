#include "animrt/runtime/robot_loader.hpp"

#include <algorithm>
#include <string>

#include "animrt/bridge/protocol.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/motion_check.hpp"

namespace animrt {

namespace {

// "file:line:column" of a location in a motion file.
std::string at(const Location& where) {
  std::string text = where.file;
  if (where.line > 0) text += ":" + std::to_string(where.line);
  if (where.column > 0) text += ":" + std::to_string(where.column);
  return text;
}

std::unique_ptr<MotionSource> make_source(const MotionConfig& motion, const RobotConfig& config) {
  const std::vector<JointSpec>& joints = config.joints;
  if (motion.type == "layers") {
    std::vector<std::unique_ptr<MotionSource>> layers;
    for (const MotionConfig& layer : motion.layers) layers.push_back(make_source(layer, config));
    return make_layered_source(std::move(layers));
  }
  if (motion.type == "show") {
    const ShowFile show = load_show_file(motion.file);
    auto source = make_show_source(show, joints);
    double length = show.duration_s;
    for (const ShowTrack& track : show.tracks) length = std::max(length, track.keys.back().t);
    MotionCheck check{source.get(), length, motion.where, motion.key, {}};
    check.joint_where = [&show, &joints](int j) {
      for (const ShowTrack& track : show.tracks) {
        if (track.joint == joints[static_cast<std::size_t>(j)].name) return at(track.where);
      }
      return std::string();
    };
    check_motion(config, check);
    return source;
  }
  if (motion.type == "gait" || motion.type == "head") {
    std::unique_ptr<GaitFile> gait;
    std::unique_ptr<MotionSource> source;
    if (motion.type == "gait") {
      gait = std::make_unique<GaitFile>(load_gait_file(motion.file));
      if (gait->balance) {
        // Played without its reflex the gait would not be the walk it was
        // made for: refused before anything moves.
        // The cycle reads the trunk's attitude (imus:), but the reflex also
        // needs each leg's ground contact and its Jacobian, which the
        // runtime does not have.
        throw InputError(gait->balance->where, "balance",
                         "this gait balances through the trunk's attitude and its legs' ground "
                         "contact; the runtime reads the attitude (imus:) but does not play the "
                         "reflex yet; walk it with `animrt gait measure --physics` or remove "
                         "balance");
      }
      source = make_gait_source(*gait, joints);
    } else {
      source = head::make_head_source(*motion.head, joints);
    }
    // Gaits and head motion produce angles; only a show states metres.
    for (int j : source->driven_joints()) {
      const JointSpec& joint = joints[static_cast<std::size_t>(j)];
      if (joint.type == JointType::prismatic) {
        throw InputError(motion.where, "motion.type",
                         "a " + motion.type + " drives angles, and joint " + joint.name +
                             " is prismatic (metres); drive it with a show");
      }
    }
    // Head motion follows speech known only as it plays (live capture, or a
    // file streamed through the decoder), and its targets are clamped to the
    // joints' limits as they are made, so it is not sampled here.
    if (gait) {
      MotionCheck check{source.get(),
                        gait_check_duration(gait->stride_frequency()),
                        motion.where,
                        motion.key,
                        {}};
      check.joint_where = [&gait, &joints](int j) {
        for (const GaitJoint& g : gait->joints) {
          if (g.name == joints[static_cast<std::size_t>(j)].name)
            return at(g.where) + ": joints." + g.name;
        }
        return std::string();
      };
      check_motion(config, check);
      if (gait->steering) {
        // Over its whole range of commands, on a source of its own.
        const auto steered = make_gait_source(*gait, joints);
        check_steered_motion(config, check, *steered, *gait->steering);
      }
    }
    return source;
  } else {
    throw InputError(motion.where, "motion.type", "unsupported motion type " + quote(motion.type));
  }
}

}  // namespace

LoadedRobot load_robot(const std::string& path) {
  LoadedRobot robot;
  robot.config = load_robot_config(path);
  robot.motion = make_source(robot.config.motion, robot.config);
  if (robot.config.motion.type == "gait") {
    robot.steering = load_gait_file(robot.config.motion.file).steering;
  }
  return robot;
}

std::vector<std::string> device_guard_notes(const RobotConfig& config) {
  std::vector<std::string> notes;
  for (const BusConfig& bus : config.buses) {
    const Protocol* protocol = find_protocol(bus.protocol);
    const std::string note = protocol != nullptr ? protocol->device_guard_note(bus) : "";
    if (!note.empty()) notes.push_back("bus " + bus.name + " (" + bus.protocol + "): " + note);
  }
  return notes;
}

}  // namespace animrt
