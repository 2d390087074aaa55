#pragma once
// The seam between the evolver and a physics engine: a simulator walks a
// model with a gait for some stride cycles and reports what happened. The
// MuJoCo implementation lives in sim/mujoco; the evolver never sees it.
//
// A simulator is used by one thread at a time; a factory makes one per
// worker thread (they may share the read-only model).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/core/joint.hpp"

namespace animrt::evolve {

struct WalkSettings {
  double settle_s = 0.5;   // standing still in the gait's first pose before walking
  int warmup_cycles = 1;   // stride cycles walked but not measured
  int measure_cycles = 3;  // stride cycles measured
  // Nonzero: every joint starts off its standing angle by up to
  // `perturb_rad`, drawn from this seed, so repeated walks show how robust a
  // gait is rather than replaying one exact start.
  std::uint64_t perturb_seed = 0;
  double perturb_rad = 0.0;
  // The balance reflex reads the trunk's attitude this long ago (s), as a
  // runtime whose IMU reports late does. A measure of how the law stands a
  // delay, not the fitness (which reads the attitude of the step: 0).
  double balance_delay_s = 0.0;
  // The reflex reads the attitude once every this long (s), as from an IMU
  // reporting at that rate, and holds tilt and rate between; up to a
  // physics step: every step (the fitness). A measure, like the delay.
  double balance_period_s = 0.0;
  // Nonempty (one per actuated joint, ModelInfo::joints' order): the walk
  // plays its targets (gait and reflex) through the runtime's safety filter
  // with these limits, stepped every `limits_period_s` (the robot's loop
  // period; the actuators hold a command between steps, as a servo holds its
  // goal), so a gait is scored as the runtime plays it. Empty: the targets
  // reach the actuators every physics step as they are (the fitness).
  std::vector<JointLimits> joint_limits;
  double limits_period_s = 0.005;
};

struct GaitMeasures {
  bool fell = false;              // torso too low, flipped, or the physics went unstable
  double speed = 0.0;             // m/s, forward (+x) displacement of the torso / time
  double distance = 0.0;          // m, forward displacement over the measured cycles
  double stride_length = 0.0;     // m, mean forward advance of a foot between its touchdowns
  double duty_factor = 0.0;       // mean fraction of the stride each foot is on the ground
  double energy_per_cycle = 0.0;  // J, sum |actuator force x joint velocity| dt per cycle
  double max_tilt_deg = 0.0;      // largest tilt of the torso from upright while measured
  double sim_time = 0.0;          // s simulated
  long steps = 0;                 // physics steps taken
};

// What a model looks like to the fitness function.
struct ModelInfo {
  std::vector<std::string> joints;  // actuated joints, by name
  double hip_height_m = 0.0;        // standing hip height
  double mass_kg = 0.0;
};

class GaitSimulator {
 public:
  virtual ~GaitSimulator() = default;
  virtual const ModelInfo& info() const = 0;
  // Walks `gait` (validated; its joints are model joints) from a standing
  // start. Never throws for a bad gait: a gait that breaks the model falls.
  virtual GaitMeasures walk(const GaitFile& gait, const WalkSettings& settings) = 0;
};

class GaitSimulatorFactory {
 public:
  virtual ~GaitSimulatorFactory() = default;
  virtual std::unique_ptr<GaitSimulator> make() const = 0;
};

}  // namespace animrt::evolve
