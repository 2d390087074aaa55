#include "animrt/bridge/bus_config.hpp"

#include <cmath>

namespace animrt {

std::int32_t ActuatorBinding::to_ticks(double rad) const {
  return static_cast<std::int32_t>(std::lround(zero_ticks + direction * rad * ticks_per_rad));
}

double ActuatorBinding::to_rad(std::int32_t ticks) const {
  return direction * (static_cast<double>(ticks) - zero_ticks) / ticks_per_rad;
}

}  // namespace animrt
