#pragma once
// A smooth move between two poses (quintic: zero velocity and acceleration at
// both ends), long enough that no joint needs more than its velocity or
// acceleration limit. Used for the start ramp (measured pose -> first pose of
// the motion) and the stop ramp (current pose -> home).

#include <span>
#include <vector>

#include "animrt/core/joint.hpp"

namespace animrt {

class PoseRamp {
 public:
  PoseRamp() = default;
  explicit PoseRamp(std::size_t joints) : from_(joints, 0.0), to_(joints, 0.0) {}

  // Plans a ramp of at least `min_duration` seconds. Allocation-free when the
  // sizes match the constructor's.
  void plan(std::span<const double> from, std::span<const double> to,
            std::span<const JointLimits> limits, double min_duration);

  // Pose at `t` seconds since the ramp began (held at `to` afterwards).
  void sample(double t, std::span<double> pose) const;
  double duration() const { return duration_; }

 private:
  std::vector<double> from_;
  std::vector<double> to_;
  double duration_ = 0.0;
};

}  // namespace animrt
