#pragma once
// What an IMU tells the cycle, in SI and in the figure's trunk frame (x
// forward, y left, z up), whatever part and mounting measured it. Plain data
// so that the cycle, the safety watch and a motion source (a gait's balance
// reflex) read the same numbers, and none of them knows the bus.

#include <algorithm>
#include <array>
#include <cmath>

namespace animrt {

struct ImuReading {
  // Attitude of the trunk in the world (w, x, y, z), yaw about the world's
  // vertical first, then pitch, then roll.
  std::array<double, 4> quat{1.0, 0.0, 0.0, 0.0};
  std::array<double, 3> rate_rad_s{};  // angular rate in the trunk frame
  std::array<double, 3> accel_m_s2{};  // specific force in the trunk frame
  double time_s = 0.0;                 // run time the part measured it
};

// The world-vertical (z) components of the trunk's forward and left axes:
// the sines of the nose and of the left side being up.
struct TrunkUp {
  double nose_up = 0.0;
  double left_up = 0.0;
  double up_up = 1.0;  // world z of the trunk's own z axis (cos of the tilt)
};

inline TrunkUp trunk_up(const std::array<double, 4>& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  // Third row of the rotation matrix (world = R * body).
  return TrunkUp{2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)};
}

// Quaternion (w, x, y, z) of yaw about z, then pitch about y, then roll about x.
inline std::array<double, 4> quat_from_ypr(double yaw, double pitch, double roll) {
  const double cy = std::cos(0.5 * yaw), sy = std::sin(0.5 * yaw);
  const double cp = std::cos(0.5 * pitch), sp = std::sin(0.5 * pitch);
  const double cr = std::cos(0.5 * roll), sr = std::sin(0.5 * roll);
  return {cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
          cr * cp * sy - sr * sp * cy};
}

// Roll and pitch (rad) of a quaternion, as quat_from_ypr takes them.
inline double roll_of(const std::array<double, 4>& q) {
  return std::atan2(2.0 * (q[0] * q[1] + q[2] * q[3]), 1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2]));
}
inline double pitch_of(const std::array<double, 4>& q) {
  const double s = 2.0 * (q[0] * q[2] - q[3] * q[1]);
  return std::asin(std::clamp(s, -1.0, 1.0));
}
inline double yaw_of(const std::array<double, 4>& q) {
  return std::atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
}

inline std::array<double, 4> quat_mul(const std::array<double, 4>& a,
                                      const std::array<double, 4>& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
          a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
          a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}
inline std::array<double, 4> quat_conj(const std::array<double, 4>& q) {
  return {q[0], -q[1], -q[2], -q[3]};
}

// The trunk's tilt from upright (rad): the angle between its z axis and the
// world's vertical.
inline double tilt_of(const std::array<double, 4>& q) {
  return std::acos(std::clamp(trunk_up(q).up_up, -1.0, 1.0));
}

}  // namespace animrt
