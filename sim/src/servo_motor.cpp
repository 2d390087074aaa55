#include "animrt/sim/servo_motor.hpp"

#include <algorithm>
#include <cmath>

namespace animrt::sim {

ServoMotor ServoMotor::after(double dt_s, double goal, double vmax, double tau_s) const {
  ServoMotor m = *this;
  double dt = dt_s;
  const double error = goal - m.position;
  const double dir = error >= 0 ? 1.0 : -1.0;
  if (tau_s <= 0) {  // pure rate limiter
    const double travel = std::min(std::abs(error), vmax * dt);
    m.position += dir * travel;
    m.velocity = m.position == goal ? 0.0 : dir * vmax;
    return m;
  }
  // A ramp at vmax until the error is vmax * tau, then an exponential decay.
  const double band = vmax * tau_s;
  if (std::abs(error) > band) {
    const double ramp_s = (std::abs(error) - band) / vmax;
    if (dt <= ramp_s) {
      m.position += dir * vmax * dt;
      m.velocity = dir * vmax;
      return m;
    }
    m.position = goal - dir * band;
    dt -= ramp_s;
  }
  const double remaining = (goal - m.position) * std::exp(-dt / tau_s);
  m.position = goal - remaining;
  m.velocity = remaining / tau_s;
  return m;
}

}  // namespace animrt::sim
