#pragma once
// The `steering` section of a gait file (docs/gait.md): the range of
// commands a steerable gait accepts and what it needs to turn them into
// stride frequency, stride length and a turn.

#include <string>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt {

struct GaitSteering {
  double min_froude = 0.0;             // slowest walking Froude number (> 0)
  double max_froude = 0.0;             // fastest
  double max_turn_rad_s = 0.0;         // fastest turn rate, either way (degrees/s in the file)
  double max_acceleration_m_s2 = 0.0;  // forward speed changes at most this fast
  double hip_height_m = 0.0;           // h of Fr = v / sqrt(g h)
  double track_width_m = 0.0;          // between the left and the right feet
  std::vector<std::string> left;       // limb names on the left side
  std::vector<std::string> right;      // and on the right
  // Hip yaw joints (robot joints the gait maps): their curve is the motion at
  // the fastest turn to the left, scaled by turn / max turn.
  std::vector<std::string> yaw_joints;
  Location where;  // of the `steering` key; ignored by ==

  double min_speed_m_s() const;
  double max_speed_m_s() const;
};

bool operator==(const GaitSteering& a, const GaitSteering& b);

}  // namespace animrt
