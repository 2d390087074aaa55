#pragma once
// Load-time check of a motion over its whole length: before anything moves,
// every target it will produce is sampled at the loop rate and must be
// finite, stay within each joint's limits (give or take a small margin; the
// safety filter clamps the rest), and its first pose must be reachable from
// the home pose by a start ramp no longer than safety.start_ramp_max_s.

#include <functional>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_steering.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {

// How far past a limit a target may go before the motion is refused: the
// larger of 2 degrees (2 mm for a prismatic joint) and 5 % of the range.
double limit_margin(const JointSpec& joint);

struct MotionCheck {
  const MotionSource* source = nullptr;
  double duration_s = 0.0;  // sampled over [0, duration_s] at the loop rate
  Location where;           // the motion's key in the robot file
  std::string key;          // e.g. "motion.file" or "motion.layers[1].file"
  // Where the motion file defines a robot joint's motion ("" when unknown),
  // e.g. "walk.yaml:14:3: joints.lf_hip".
  std::function<std::string(int joint)> joint_where;
  // When set: per joint, the fastest the motion moves it from one cycle to
  // the next (rad/s or m/s) and when, raised to what this check sees.
  struct Speeds {
    std::vector<double> peak, at_s;
  };
  Speeds* speeds = nullptr;
};

// Throws InputError at check.where / check.key on the first problem.
void check_motion(const RobotConfig& config, const MotionCheck& check);

// One command of the steering check: given at time t.
struct SteeringStep {
  double t = 0.0;
  MotionCommand command;
};

// The commands a steerable gait is checked under, in order: fastest and
// slowest speed straight and at the fastest turn both ways, standing, mid
// speed, and steps between them, each held long enough to reach it; the
// last step's t is the plan's length.
std::vector<SteeringStep> steering_check_plan(const GaitSteering& steering);

// check_motion() for `source`, a steerable gait, steered through
// steering_check_plan(steering) (check.source and check.duration_s are
// ignored). Messages name the command in force. Leaves `source` steered:
// check a source of its own, not the one that will run.
void check_steered_motion(const RobotConfig& config, const MotionCheck& check, MotionSource& source,
                          const GaitSteering& steering);

// The length a gait is checked over: 20 strides, at least 60 s, at most 600 s.
double gait_check_duration(double stride_frequency_hz);

}  // namespace animrt
