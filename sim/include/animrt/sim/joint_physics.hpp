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

  // Lockstep runs (a simulated clock). Several buses drive one figure, each
  // on its own thread: a bus that steps the physics on to the next cycle
  // before another bus has handed over that bus's goals of this cycle would
  // make the run depend on thread timing. So each bus joins as a party and
  // reports the time of every packet it handles (reach); the physics never
  // steps past the party furthest behind, and a party ahead waits for the
  // others for a bounded wall time (then the others are passed over until
  // they report again, so a bus that stopped talking costs one wait, not one
  // per packet). A party that leaves is no longer waited for.
  virtual int join_lockstep() { return -1; }
  virtual void reach([[maybe_unused]] int party, [[maybe_unused]] Nanos now) {}
  virtual void leave_lockstep([[maybe_unused]] int party) {}
};

}  // namespace animrt::sim
