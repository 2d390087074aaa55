#include "animrt/runtime/pose_ramp.hpp"

#include <algorithm>
#include <cmath>

namespace animrt {
namespace {
// Peak velocity and acceleration of s(u) = 10u^3 - 15u^4 + 6u^5 over a unit
// move in unit time.
constexpr double kPeakVelocity = 1.875;
constexpr double kPeakAcceleration = 5.7735026918962576;  // 10/sqrt(3)
}  // namespace

void PoseRamp::plan(std::span<const double> from, std::span<const double> to,
                    std::span<const JointLimits> limits, double min_duration) {
  double duration = std::max(min_duration, 0.0);
  for (std::size_t i = 0; i < from.size(); ++i) {
    from_[i] = from[i];
    to_[i] = to[i];
    const double distance = std::abs(to[i] - from[i]);
    // 10 % headroom so the safety filter is never the one doing the limiting.
    duration = std::max(duration, 1.1 * kPeakVelocity * distance / limits[i].max_velocity);
    duration = std::max(duration,
                        1.1 * std::sqrt(kPeakAcceleration * distance / limits[i].max_acceleration));
  }
  duration_ = duration;
}

void PoseRamp::sample(double t, std::span<double> pose) const {
  double u = duration_ > 0.0 ? std::clamp(t / duration_, 0.0, 1.0) : 1.0;
  const double s = u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
  for (std::size_t i = 0; i < from_.size(); ++i) pose[i] = from_[i] + s * (to_[i] - from_[i]);
}

}  // namespace animrt
