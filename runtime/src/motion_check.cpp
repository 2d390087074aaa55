#include "animrt/runtime/motion_check.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "animrt/controllers/gait/froude.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "animrt/runtime/pose_ramp.hpp"

namespace animrt {
namespace {

// Within the margin the safety filter clamps (a cubic segment overshooting
// its keys a little); what is refused is motion far outside the limits.
constexpr double kMarginFraction = 0.05;
constexpr double kMarginDeg = 2.0;
constexpr double kMarginM = 0.002;
// Enough for a minute at 10 kHz; longer motions are sampled more coarsely.
constexpr double kMaxSamples = 600000.0;

struct Unit {
  double per_si;
  const char* name;
};
Unit unit_of(const JointSpec& joint) {
  if (joint.type == JointType::prismatic) return {1.0, "m"};
  return {rad_to_deg(1.0), "deg"};
}

std::string number(double v) {
  if (std::isnan(v)) return "NaN";  // the sign of a NaN says nothing
  std::ostringstream out;
  out.precision(6);
  out << v;
  return out.str();
}

std::string in_unit(const JointSpec& joint, double si) {
  const Unit u = unit_of(joint);
  return number(si * u.per_si) + " " + u.name;
}

std::string range_text(const JointSpec& joint) {
  const Unit u = unit_of(joint);
  return number(joint.limits.min_position * u.per_si) + ".." +
         number(joint.limits.max_position * u.per_si) + " " + u.name;
}

std::string joint_text(const MotionCheck& check, const JointSpec& joint, int index) {
  std::string text = "joint " + joint.name;
  if (check.joint_where) {
    if (const std::string at = check.joint_where(index); !at.empty()) text += " (" + at + ")";
  }
  return text;
}

}  // namespace

double limit_margin(const JointSpec& joint) {
  const double range = joint.limits.max_position - joint.limits.min_position;
  const double floor = joint.type == JointType::prismatic ? kMarginM : deg_to_rad(kMarginDeg);
  return std::max(floor, kMarginFraction * range);
}

double gait_check_duration(double stride_frequency_hz) {
  const double strides = stride_frequency_hz > 0.0 ? 20.0 / stride_frequency_hz : 60.0;
  return std::clamp(strides, 60.0, 600.0);
}

namespace {

// Samples check.source over [0, check.duration_s]; `before(t)` runs before
// each sample (steering), `context()` is appended to every message.
void sample_motion(const RobotConfig& config, const MotionCheck& check,
                   const std::function<void(double)>& before,
                   const std::function<std::string()>& context) {
  const auto fail = [&](const std::string& message) {
    throw InputError(check.where, check.key, message + (context ? context() : std::string()));
  };
  const std::size_t n = config.joints.size();
  std::vector<double> home(n), pose(n);
  std::vector<JointLimits> limits(n);
  std::vector<double> margin(n);
  for (std::size_t j = 0; j < n; ++j) {
    home[j] = config.joints[j].home;
    limits[j] = config.joints[j].limits;
    margin[j] = limit_margin(config.joints[j]);
  }
  const auto driven = check.source->driven_joints();

  const double period = 1.0 / config.rate_hz;
  const double step = std::max(period, check.duration_s / kMaxSamples);
  const auto samples = static_cast<long>(std::ceil(check.duration_s / step));
  MotionCheck::Speeds* speeds = check.speeds;
  if (speeds) {
    speeds->peak.resize(n, 0.0);
    speeds->at_s.resize(n, 0.0);
  }
  std::vector<double> previous(n);
  double previous_t = 0.0;
  for (long k = 0; k <= samples; ++k) {
    const double t = std::min(static_cast<double>(k) * step, check.duration_s);
    pose = home;
    if (before) before(t);
    check.source->sample(t, pose);
    // Speeds between samples one loop period apart (a coarser sampling of a
    // long motion would understate them).
    if (speeds && k > 0 && t - previous_t > 0.0 && t - previous_t <= 1.001 * period) {
      for (int j : driven) {
        const auto i = static_cast<std::size_t>(j);
        const double v = std::abs(pose[i] - previous[i]) / (t - previous_t);
        if (std::isfinite(v) && v > speeds->peak[i]) {
          speeds->peak[i] = v;
          speeds->at_s[i] = t;
        }
      }
    }
    previous = pose;
    previous_t = t;
    for (int j : driven) {
      const auto i = static_cast<std::size_t>(j);
      const JointSpec& joint = config.joints[i];
      const double v = pose[i];
      if (!std::isfinite(v)) {
        fail(joint_text(check, joint, j) + " is not finite (" + number(v) +
             ") at t = " + number(t) + " s");
      }
      if (v < limits[i].min_position - margin[i] || v > limits[i].max_position + margin[i]) {
        fail(joint_text(check, joint, j) + " reaches " + in_unit(joint, v) +
             " at t = " + number(t) + " s, outside its limits " + range_text(joint) +
             " by more than the " + in_unit(joint, margin[i]) + " margin");
      }
    }
    if (k == 0) {
      // The start ramp at run time begins from the measured pose; from home
      // is what a figure at rest needs.
      PoseRamp ramp(n);
      ramp.plan(home, pose, limits, config.safety.start_ramp_s);
      if (ramp.duration() > config.safety.start_ramp_max_s) {
        std::size_t worst = 0;
        double worst_s = -1.0;
        for (int j : driven) {
          const auto i = static_cast<std::size_t>(j);
          PoseRamp one(1);
          one.plan(std::span(&home[i], 1), std::span(&pose[i], 1), std::span(&limits[i], 1), 0.0);
          if (one.duration() > worst_s) {
            worst_s = one.duration();
            worst = i;
          }
        }
        const JointSpec& joint = config.joints[worst];
        fail("the start ramp from the home pose to the first pose takes " +
             number(ramp.duration()) + " s, longer than safety.start_ramp_max_s (" +
             number(config.safety.start_ramp_max_s) + " s); " +
             joint_text(check, joint, static_cast<int>(worst)) + " starts at " +
             in_unit(joint, pose[worst]) + ", home " + in_unit(joint, home[worst]));
      }
    }
  }
}

}  // namespace

}  // namespace animrt

namespace animrt {

void check_motion(const RobotConfig& config, const MotionCheck& check) {
  sample_motion(config, check, {}, {});
}

std::vector<SteeringStep> steering_check_plan(const GaitSteering& s) {
  const double lo = s.min_speed_m_s(), hi = s.max_speed_m_s(), mid = 0.5 * (lo + hi);
  const double w = s.max_turn_rad_s;
  // Long enough to reach any command from any other and walk two strides.
  const double stride_s = 1.0 / froude_stride_frequency(s.min_froude, s.hip_height_m);
  const double hold = 2.0 * stride_s + (hi / s.max_acceleration_m_s2) + stride_s;
  std::vector<MotionCommand> commands = {{hi, 0.0}, {hi, w},    {hi, -w},   {lo, 0.0}, {lo, w},
                                         {lo, -w},  {0.0, 0.0}, {mid, 0.0}, {mid, w},  {hi, -w},
                                         {lo, w},   {0.0, 0.0}, {hi, 0.0}};
  // Turns on the spot, both ways, and into and out of walking.
  if (s.turn_on_the_spot)
    commands.insert(commands.end(), {{0.0, w}, {lo, -w}, {0.0, -w}, {0.0, w}, {0.0, 0.0}});
  std::vector<SteeringStep> plan;
  double t = 0.0;
  for (const MotionCommand& c : commands) {
    plan.push_back({t, c});
    t += hold;
  }
  plan.push_back({t, {0.0, 0.0}});  // end: the plan's length
  return plan;
}

void check_steered_motion(const RobotConfig& config, const MotionCheck& check, MotionSource& source,
                          const GaitSteering& steering) {
  const std::vector<SteeringStep> plan = steering_check_plan(steering);
  MotionCheck steered = check;
  steered.source = &source;
  steered.duration_s = plan.back().t;
  std::size_t next = 0;
  MotionCommand current{};
  sample_motion(
      config, steered,
      [&](double t) {
        while (next + 1 < plan.size() && plan[next].t <= t) {
          current = plan[next].command;
          source.steer(current);
          ++next;
        }
      },
      [&] {
        return " (steered: speed " + number(current.speed_m_s) + " m/s, turn " +
               number(rad_to_deg(current.turn_rad_s)) + " deg/s)";
      });
}

}  // namespace animrt
