#pragma once
// A physics model that simulated servos can take their motor state from
// instead of their built-in motor model: a servo hands over its goal and
// torque state, and reads back its joint's position and velocity. One model
// is shared by every servo of a figure (and by several buses), so every call
// is safe from any thread.

#include <string>

#include "animrt/core/clock.hpp"

namespace animrt::sim {

class JointPhysics {
 public:
  virtual ~JointPhysics() = default;
  // Index of a robot joint in the model, or -1 if the model does not drive it.
  virtual int joint_index(const std::string& joint) const = 0;
  // Steps the physics on to `now` at its own timestep (never back).
  virtual void advance(Nanos now) = 0;
  // From now on, joint `index` is driven to `goal_rad` (torque on) or limp.
  virtual void command(int index, double goal_rad, bool torque_on) = 0;
  virtual double position(int index) const = 0;  // rad
  virtual double velocity(int index) const = 0;  // rad/s
};

}  // namespace animrt::sim
