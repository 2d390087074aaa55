#pragma once
// Gait timing from the Froude number (dynamic similarity: animals moving at
// equal Froude numbers move alike, so one number sets speed and stride for
// any leg length).
//
// Convention (as in the gait-optimisation work this layer follows):
//   Fr = v / sqrt(g h)            h = hip height above the ground
// Stride length from Alexander's relation, whose argument v^2/(g h) is Fr^2
// in this convention:
//   lambda / h = 2.3 (v^2 / (g h))^0.3
// Stride frequency f = v / lambda.
//
// All arguments must be positive and finite (callers validate their input);
// units are SI.

#include <cmath>

namespace animrt {

constexpr double kStandardGravity = 9.81;  // m/s^2

// Forward speed (m/s).
inline double froude_velocity(double froude, double hip_height_m, double g = kStandardGravity) {
  return froude * std::sqrt(g * hip_height_m);
}

// Stride length (m): distance covered in one full stride cycle.
inline double froude_stride_length(double froude, double hip_height_m,
                                   double g = kStandardGravity) {
  const double v = froude_velocity(froude, hip_height_m, g);
  return 2.3 * hip_height_m * std::pow(v * v / (g * hip_height_m), 0.3);
}

// Stride frequency (Hz): stride cycles per second.
inline double froude_stride_frequency(double froude, double hip_height_m,
                                      double g = kStandardGravity) {
  return froude_velocity(froude, hip_height_m, g) / froude_stride_length(froude, hip_height_m, g);
}

// The Froude number whose stride frequency is `frequency_hz` (the inverse of
// froude_stride_frequency: f = Fr^0.4 sqrt(g / h) / 2.3).
inline double froude_for_stride_frequency(double frequency_hz, double hip_height_m,
                                          double g = kStandardGravity) {
  return std::pow(2.3 * frequency_hz * std::sqrt(hip_height_m / g), 2.5);
}

}  // namespace animrt
