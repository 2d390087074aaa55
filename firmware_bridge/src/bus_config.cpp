#include "animrt/bridge/bus_config.hpp"

#include <cmath>

namespace animrt {

std::int32_t ActuatorBinding::to_ticks(double rad) const {
  return static_cast<std::int32_t>(std::lround(zero_ticks + direction * rad * ticks_per_rad));
}

double ActuatorBinding::safe_goal(double goal, double held) const {
  if (!std::isfinite(goal)) return held;
  if (goal < min_position) return min_position;
  if (goal > max_position) return max_position;
  return goal;
}

bool ActuatorBinding::has_limits() const {
  return std::isfinite(min_position) && std::isfinite(max_position) && min_position <= max_position;
}

double ActuatorBinding::to_rad(std::int32_t ticks) const {
  return direction * (static_cast<double>(ticks) - zero_ticks) / ticks_per_rad;
}

}  // namespace animrt
