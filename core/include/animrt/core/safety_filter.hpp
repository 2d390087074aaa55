#pragma once
// Sits between the motion source and the buses. Each cycle it turns a target
// pose into a command that
//   - never leaves the position limits (braking early enough to stop at them),
//   - never exceeds the velocity limit,
//   - never changes velocity by more than the acceleration limit allows,
// so a jump in the target (a new motion, a fault, a stop) never becomes a
// jump in the command. Allocation-free after construction.
// Core, not the loop: the fitness walk (sim/mujoco) plays its targets through
// it too, so a gait is scored as the runtime plays it.

#include <cstdint>
#include <span>
#include <vector>

#include "animrt/core/joint.hpp"

namespace animrt {

class SafetyFilter {
 public:
  SafetyFilter(std::vector<JointLimits> limits, double dt);

  // Starts from a measured pose at rest. A joint measured outside its limits
  // is brought back inside at bounded velocity and acceleration, never
  // snapped.
  void reset(std::span<const double> measured);

  // One cycle: moves the command toward `targets` (rad or m) within the limits and
  // writes it to `commands`. A joint whose entry in `active` is 0 (its bus is
  // late and takes no write this cycle) holds its last command and comes to
  // rest there: the device, which keeps its last goal, has stopped too, so
  // the joint resumes from standstill instead of jumping ahead. A target that
  // is not finite holds the joint as well; the filter's state never becomes
  // non-finite.
  void step(std::span<const double> targets, std::span<double> commands,
            std::span<const std::uint8_t> active = {});

  std::span<const double> position() const { return position_; }
  std::span<const double> velocity() const { return velocity_; }
  double dt() const { return dt_; }

 private:
  std::vector<JointLimits> limits_;
  double dt_;
  std::vector<double> position_;
  std::vector<double> velocity_;
  std::vector<double> last_target_;
  bool have_last_target_ = false;
};

// Highest speed for the next cycle from which a joint can still stop within
// `distance` (this cycle's move included) when speed changes by at most
// `accel_step` per cycle of length dt. Exact at the cycle level: if a joint
// moves at this speed, the speed one step lower is the bound next cycle.
double stopping_speed(double distance, double accel_step, double dt);

}  // namespace animrt
