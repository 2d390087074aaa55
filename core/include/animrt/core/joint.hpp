#pragma once
// Joint space: names, kinds, limits and home pose. Everything is SI inside
// the program (radians, rad/s, rad/s^2 for a revolute joint; metres, m/s,
// m/s^2 for a prismatic one); device units live in firmware_bridge.

#include <string>

namespace animrt {

// A revolute joint turns (positions in rad); a prismatic joint slides
// (positions in m), e.g. a linear actuator driven directly.
enum class JointType { revolute, prismatic };

struct JointLimits {
  double min_position = 0.0;      // rad (prismatic: m)
  double max_position = 0.0;      // rad (m)
  double max_velocity = 0.0;      // rad/s (m/s), > 0
  double max_acceleration = 0.0;  // rad/s^2 (m/s^2), > 0
};

struct JointSpec {
  std::string name;
  JointLimits limits;
  double home = 0.0;  // rad (prismatic: m), within limits
  JointType type = JointType::revolute;
};

constexpr double kPi = 3.14159265358979323846;
constexpr double deg_to_rad(double deg) { return deg * (kPi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / kPi); }

}  // namespace animrt
