#include "animrt/runtime/robot_loader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "animrt/bridge/protocol.hpp"
#include "animrt/controllers/gait/balanced_gait_source.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/motion_check.hpp"
#include "animrt/runtime/robot_model.hpp"

namespace animrt {

namespace {

// "file:line:column" of a location in a motion file.
std::string at(const Location& where) {
  std::string text = where.file;
  if (where.line > 0) text += ":" + std::to_string(where.line);
  if (where.column > 0) text += ":" + std::to_string(where.column);
  return text;
}

// A gait with `balance:` plays its reflex on the trunk's IMU (the first of
// imus:) through the legs of the figure's model (model:): without either it
// would not be the walk that was scored, so it is refused before anything moves.
void check_balance(const GaitBalance& balance, const RobotConfig& config) {
  if (config.imus.empty()) {
    throw InputError(balance.where, "balance",
                     "this gait balances on the trunk's attitude, and " + config.file +
                         " has no IMU: give it one under imus: (the first is the trunk's), or "
                         "remove balance");
  }
  if (config.model.empty()) {
    throw InputError(balance.where, "balance",
                     "this gait stretches the legs through the figure's model, and " + config.file +
                         " names none: give it model: (the figure's MJCF), or remove balance");
  }
}

std::unique_ptr<MotionSource> make_source(const MotionConfig& motion, const RobotConfig& config,
                                          MotionCheck::Speeds& speeds,
                                          std::vector<std::string>& warnings) {
  const std::vector<JointSpec>& joints = config.joints;
  if (motion.type == "layers") {
    std::vector<std::unique_ptr<MotionSource>> layers;
    for (const MotionConfig& layer : motion.layers) {
      layers.push_back(make_source(layer, config, speeds, warnings));
      if (dynamic_cast<BalancedGaitSource*>(layers.back().get())) {
        throw InputError(layer.where, layer.key,
                         "a gait with balance: stretches the legs under the whole figure and "
                         "plays on its own, not as a layer");
      }
    }
    return make_layered_source(std::move(layers));
  }
  if (motion.type == "show") {
    const ShowFile show = load_show_file(motion.file);
    if (show.has_learned) {
      std::string w = seqnet::interpolation_warning(*show.learned.model, show.learned.model_file);
      if (!w.empty()) warnings.push_back(w.substr(w.find(' ') + 1));  // without "warning: "
    }
    auto source = make_show_source(show, joints);
    double length = show.duration_s;
    for (const ShowTrack& track : show.tracks) length = std::max(length, track.keys.back().t);
    MotionCheck check{source.get(), length, motion.where, motion.key, {}};
    check.speeds = &speeds;
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
      if (gait->balance) check_balance(*gait->balance, config);
      source = make_gait_source(*gait, joints);
      if (gait->balance) {
        source =
            std::make_unique<BalancedGaitSource>(std::move(source), *gait->balance, joints.size());
      }
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
      check.speeds = &speeds;
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

// A motion that asks a joint for more speed than its simulated servos turn
// (sim.max_speed_dps, the model of the real ones) lags ever further behind
// and faults on the following-error watch: said on load, with the numbers.
// The safety filter never lets a joint go faster than its velocity limit,
// so that is the most the motion can ask.
void note_servo_speeds(LoadedRobot& robot, const MotionCheck::Speeds& speeds) {
  RobotConfig& config = robot.config;
  config.lag_notes.assign(config.joints.size(), "");
  if (speeds.peak.size() != config.joints.size()) return;
  for (const BusConfig& bus : config.buses) {
    const double servo = bus.sim.max_speed_rad_s;
    std::size_t worst = config.joints.size(), count = 0;
    double worst_asked = 0.0;
    for (const ActuatorBinding& a : bus.actuators) {
      const auto j = static_cast<std::size_t>(a.joint_index);
      const JointSpec& joint = config.joints[j];
      if (joint.type == JointType::prismatic) continue;
      const double asked = std::min(speeds.peak[j], joint.limits.max_velocity);
      // A tenth over: the servo's lag absorbs a brief excess.
      if (!(asked > 1.1 * servo)) continue;
      config.lag_notes[j] = fmt::format(
          "its motion asks for up to {:.0f} deg/s, faster than bus {}'s servos turn ({:.0f} deg/s, "
          "sim.max_speed_dps)",
          rad_to_deg(asked), bus.name, rad_to_deg(servo));
      ++count;
      if (asked > worst_asked) {
        worst_asked = asked;
        worst = j;
      }
    }
    if (worst == config.joints.size()) continue;
    robot.warnings.push_back(fmt::format(
        "{} asks joint {} for up to {:.0f} deg/s at t = {:.2f} s ({} joint{} of bus {} "
        "over its servos' speed), but the servos of bus {} turn at most {:.0f} deg/s "
        "(sim.max_speed_dps{}): a run would lag and fault on its following error; give "
        "sim.max_speed_dps the real servos' speed, or slow the motion",
        describe_motion(config.motion), config.joints[worst].name, rad_to_deg(worst_asked),
        speeds.at_s[worst], count, count == 1 ? "" : "s", bus.name, bus.name, rad_to_deg(servo),
        servo == SimBusSettings{}.max_speed_rad_s ? ", the default" : ""));
  }
}

// A bus's read must be back within the read budget, or the cycle goes on
// without it (a late cycle): its wire time and the measured overhead of each
// transaction against the budget, said on load with the numbers.
void note_read_budget(LoadedRobot& robot) {
  const RobotConfig& config = robot.config;
  const double period = 1.0 / config.rate_hz;
  const double budget = kReadBudgetFraction * period;
  for (const BusConfig& bus : config.buses) {
    const Protocol* protocol = find_protocol(bus.protocol);
    const double bits = protocol ? protocol->read_wire_bits_per_cycle(bus) : 0.0;
    if (bits <= 0.0) continue;
    const double wire = bits / bus.baud;
    const int transactions = protocol->read_transactions_per_cycle(bus);
    const double overhead = transactions * kReadOverheadS;
    if (wire + overhead <= budget) continue;
    robot.warnings.push_back(fmt::format(
        "bus {}: a read takes about {:.2f} ms ({:.2f} ms on the wire for {} devices at {} baud "
        "+ {:.2f} ms measured overhead for {} transaction{}), over the read budget of {:.2f} ms "
        "({:.0f} % of the {:.2f} ms period at {} Hz): expect late cycles; run at most {:.0f} Hz, "
        "raise the baud rate or split the devices over more buses",
        bus.name, (wire + overhead) * 1e3, wire * 1e3, bus.actuators.size(), bus.baud,
        overhead * 1e3, transactions, transactions == 1 ? "" : "s", budget * 1e3,
        kReadBudgetFraction * 100.0, period * 1e3, format_number(config.rate_hz),
        std::floor(kReadBudgetFraction / (wire + overhead))));
  }
}

}  // namespace

LoadedRobot load_robot(const std::string& path) {
  LoadedRobot robot;
  robot.config = load_robot_config(path);
  MotionCheck::Speeds speeds;
  robot.motion = make_source(robot.config.motion, robot.config, speeds, robot.warnings);
  note_read_budget(robot);
  note_servo_speeds(robot, speeds);
  robot.balanced = dynamic_cast<BalancedGaitSource*>(robot.motion.get());
  if (robot.config.motion.type == "gait") {
    robot.steering = load_gait_file(robot.config.motion.file).steering;
  }
  return robot;
}

std::unique_ptr<MotionSource> load_motion_source(const MotionConfig& motion,
                                                 const RobotConfig& config) {
  std::vector<std::string> warnings;
  return load_motion_source(motion, config, warnings);
}

std::unique_ptr<MotionSource> load_motion_source(const MotionConfig& motion,
                                                 const RobotConfig& config,
                                                 std::vector<std::string>& warnings) {
  MotionCheck::Speeds speeds;
  return make_source(motion, config, speeds, warnings);
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
