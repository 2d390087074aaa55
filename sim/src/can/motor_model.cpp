#include "animrt/sim/can/motor_model.hpp"

#include <algorithm>
#include <cmath>

namespace animrt::sim {

LagMotor::LagMotor(double position, double tau_s, double vmax, Nanos now)
    : position_(position), goal_(position), tau_(std::max(tau_s, 1e-6)), vmax_(vmax), time_(now) {}

void LagMotor::state_at(Nanos now, double& position, double& velocity) const {
  double dt = std::max<double>(0.0, to_seconds(now - time_));
  const double error = goal_ - position_;
  const double sign = error >= 0 ? 1.0 : -1.0;
  double e = std::abs(error);
  double p = position_;
  velocity = 0.0;
  // Saturated: at vmax until the error is small enough for the lag to take over.
  const double linear = vmax_ * tau_;
  if (e > linear) {
    const double ts = (e - linear) / vmax_;
    if (dt <= ts) {
      position = p + sign * vmax_ * dt;
      velocity = sign * vmax_;
      return;
    }
    dt -= ts;
    e = linear;
  }
  const double decay = std::exp(-dt / tau_);
  position = goal_ - sign * e * decay;
  velocity = sign * e * decay / tau_;
}

void LagMotor::advance(Nanos now) {
  if (now <= time_) return;
  double v = 0;
  state_at(now, position_, v);
  time_ = now;
}

void LagMotor::set_goal(double goal, Nanos now) {
  advance(now);
  goal_ = goal;
}

double LagMotor::position(Nanos now) const {
  double p = 0, v = 0;
  state_at(now, p, v);
  return p;
}

double LagMotor::velocity(Nanos now) const {
  double p = 0, v = 0;
  state_at(now, p, v);
  return v;
}

}  // namespace animrt::sim
