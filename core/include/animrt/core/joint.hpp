#pragma once
// Joint space: names, limits and home pose. Everything is SI (radians,
// rad/s, rad/s^2) inside the program; device units live in firmware_bridge.

#include <string>

namespace animrt {

struct JointLimits {
  double min_position = 0.0;      // rad
  double max_position = 0.0;      // rad
  double max_velocity = 0.0;      // rad/s, > 0
  double max_acceleration = 0.0;  // rad/s^2, > 0
};

struct JointSpec {
  std::string name;
  JointLimits limits;
  double home = 0.0;  // rad, within limits
};

constexpr double kPi = 3.14159265358979323846;
constexpr double deg_to_rad(double deg) { return deg * (kPi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / kPi); }

}  // namespace animrt
