#pragma once
// The motor behind a simulated CAN device: position follows a goal as a
// first-order lag (time constant tau) whose speed is limited to vmax,
// integrated in closed form so the state at a time does not depend on how
// often it was advanced on the way.

#include "animrt/core/clock.hpp"

namespace animrt::sim {

class LagMotor {
 public:
  LagMotor(double position, double tau_s, double vmax, Nanos now);
  // Brings the state to `now` (never back) and then sets the goal.
  void set_goal(double goal, Nanos now);
  void hold(Nanos now) { set_goal(position(now), now); }
  // State at `now` without changing anything.
  double position(Nanos now) const;
  double velocity(Nanos now) const;
  double goal() const { return goal_; }
  // Shifts the position (and goal) by `delta`, e.g. a new zero.
  void offset(double delta) {
    position_ += delta;
    goal_ += delta;
  }

 private:
  void advance(Nanos now);
  void state_at(Nanos now, double& position, double& velocity) const;

  double position_;
  double goal_;
  double tau_;
  double vmax_;
  Nanos time_;
};

}  // namespace animrt::sim
