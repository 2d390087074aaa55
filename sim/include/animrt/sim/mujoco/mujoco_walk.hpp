#pragma once
// Walking a steered MotionSource on a MuJoCo model with one command, and
// measuring what the torso did (for `animrt gait calibrate`).
//
// The figure starts at rest standing in the source's pose under a standing
// command (speed 0), settles, then gets `command` and walks: warm-up time,
// then measured time. The source drives the model's actuators by name (its
// joints are model_joint_specs(model)).

#include <cstdint>
#include <vector>

#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::sim {

// One JointSpec per actuator (actuator order), limits from the joint ranges.
std::vector<JointSpec> model_joint_specs(const MujocoModel& model);

struct WalkTrial {
  double settle_s = 0.5;
  double warmup_s = 3.0;
  double measure_s = 4.0;
  double sample_period_s = 0.01;  // of the recorded trajectory
  // Nonzero: each joint starts off its standing angle by up to 1 mrad,
  // drawn from this seed (a tiny perturbation that shows how repeatable a
  // point is).
  std::uint64_t seed = 0;
};

struct TorsoSample {
  double t = 0.0;  // s since the command
  double x = 0.0, y = 0.0;
  double yaw = 0.0;  // rad, unwrapped, positive to the left
};

struct WalkTrace {
  std::vector<TorsoSample> samples;  // from the command on
  bool fell = false;
  double fall_s = -1.0;  // since the command, -1 if no fall
  // Over the measured time: mean speed along the torso's heading and mean
  // yaw rate (up to the fall, if any).
  MotionCommand achieved;
};

// Walks `source` (bound to model_joint_specs(model)) under `command`.
WalkTrace walk_command(const MujocoModel& model, MotionSource& source, const MotionCommand& command,
                       const WalkTrial& trial);

}  // namespace animrt::sim
