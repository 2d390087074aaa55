#include "animrt/core/safety_filter.hpp"

#include <algorithm>
#include <cmath>

namespace animrt {

double stopping_speed(double distance, double accel_step, double dt) {
  if (distance <= 0.0) return 0.0;
  // Moving at v this cycle and then slowing by A = accel_step every cycle
  // covers dt*(v + (v-A) + ... + (v-mA)), with m the last step still above
  // zero. Find m from the continuous solution, then solve that sum for v.
  const double x = distance / dt;
  const double n = std::sqrt(0.25 + 2.0 * x / accel_step) - 0.5;
  const double m = std::floor(n);
  return (x + accel_step * m * (m + 1.0) / 2.0) / (m + 1.0);
}

SafetyFilter::SafetyFilter(std::vector<JointLimits> limits, double dt)
    : limits_(std::move(limits)),
      dt_(dt),
      position_(limits_.size(), 0.0),
      velocity_(limits_.size(), 0.0),
      last_target_(limits_.size(), 0.0) {}

void SafetyFilter::reset(std::span<const double> measured) {
  for (std::size_t i = 0; i < limits_.size(); ++i) {
    position_[i] = measured[i];
    velocity_[i] = 0.0;
    last_target_[i] = measured[i];
  }
  have_last_target_ = false;
}

void SafetyFilter::step(std::span<const double> targets, std::span<double> commands,
                        std::span<const std::uint8_t> active) {
  for (std::size_t i = 0; i < limits_.size(); ++i) {
    const JointLimits& lim = limits_[i];
    const double accel_step = lim.max_acceleration * dt_;
    const double p = position_[i];
    const double v = velocity_[i];

    const bool finite = std::isfinite(targets[i]);
    if ((!active.empty() && !active[i]) || !finite) {
      velocity_[i] = 0.0;
      if (finite) last_target_[i] = std::clamp(targets[i], lim.min_position, lim.max_position);
      commands[i] = p;
      continue;
    }
    const double target = std::clamp(targets[i], lim.min_position, lim.max_position);
    // Feed-forward the target's own velocity so a smooth motion is tracked
    // without lag, plus a correction that can always brake onto the target.
    const double target_velocity = have_last_target_ ? (target - last_target_[i]) / dt_ : 0.0;
    last_target_[i] = target;
    const double lag = target - p - target_velocity * dt_;  // error left after feed-forward
    const double correction = std::copysign(stopping_speed(std::abs(lag), accel_step, dt_), lag);
    double wanted = target_velocity + correction;

    wanted = std::clamp(wanted, -lim.max_velocity, lim.max_velocity);
    // Never faster than what still stops at a position limit.
    wanted = std::min(wanted, stopping_speed(lim.max_position - p, accel_step, dt_));
    wanted = std::max(wanted, -stopping_speed(p - lim.min_position, accel_step, dt_));
    // Outside a limit (possible only at start): head back in, gently.
    if (p > lim.max_position) wanted = std::min(wanted, 0.0);
    if (p < lim.min_position) wanted = std::max(wanted, 0.0);

    double v_next = v + std::clamp(wanted - v, -accel_step, accel_step);
    double p_next = p + v_next * dt_;
    // Last guard against rounding: never beyond a limit we were inside of.
    const double lo = std::min(lim.min_position, p);
    const double hi = std::max(lim.max_position, p);
    if (p_next > hi || p_next < lo) {
      p_next = std::clamp(p_next, lo, hi);
      v_next = (p_next - p) / dt_;
    }
    if (!std::isfinite(p_next) || !std::isfinite(v_next)) {  // degenerate limits: hold
      p_next = p;
      v_next = 0.0;
    }
    position_[i] = p_next;
    velocity_[i] = v_next;
    commands[i] = p_next;
  }
  have_last_target_ = true;
}

}  // namespace animrt
