#include "animrt/bridge/serial_servo/servo_positions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace animrt::servo {

void ServoPositions::init(const BusConfig& config, std::int32_t min_ticks, std::int32_t max_ticks) {
  bus_ = config.name;
  bindings_ = config.actuators;
  const std::size_t n = config.actuators.size();
  present_.resize(n);
  goal_.resize(n);
  window_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config.actuators[i];
    present_[i] = goal_[i] = b.zero_ticks;
    window_[i] = GoalWindow::for_joint(b, min_ticks, max_ticks);
  }
  fresh_ = false;
}

std::string ServoPositions::start(const StatusBook& book, const char* limits_name) {
  std::string outside;
  for (std::size_t i = 0; i < present_.size(); ++i) {
    // Goals may lead from where the joint rests to its limits, never farther.
    const std::string at = window_[i].start_at(bindings_[i], present_[i]);
    if (!at.empty()) outside += (outside.empty() ? "" : "; ") + book.describe(i) + " is at " + at;
  }
  if (outside.empty()) return outside;
  outside = outside_limits_warning(outside, limits_name);
  std::fprintf(stderr, "warning: bus %s: %s\n", bus_.c_str(), outside.c_str());
  return outside;
}

ServoPositions::Span ServoPositions::limit_ticks(std::size_t device, std::int32_t top) const {
  const ActuatorBinding& b = bindings_[device];
  const std::int32_t a = b.to_ticks(b.min_position);
  const std::int32_t c = b.to_ticks(b.max_position);
  const std::int32_t at = present_[device];
  return {std::clamp(std::min({a, c, at}), 0, top), std::clamp(std::max({a, c, at}), 0, top)};
}

void ServoPositions::hand_out_found(std::span<double> positions) {
  if (!fresh_) return;
  for (std::size_t i = 0; i < std::min(positions.size(), present_.size()); ++i) {
    positions[i] = bindings_[i].to_rad(present_[i]);
  }
  fresh_ = false;
}

void ServoPositions::measured(std::size_t device, std::int32_t ticks, std::span<double> positions) {
  present_[device] = ticks;
  if (device < positions.size()) positions[device] = bindings_[device].to_rad(ticks);
}

std::int32_t ServoPositions::take_goal(std::size_t device, double rad) {
  if (!std::isfinite(rad)) return goal_[device];  // hold the last goal
  goal_[device] = bindings_[device].to_ticks(window_[device].clamp(rad));
  window_[device].narrow(rad);
  return goal_[device];
}

}  // namespace animrt::servo
