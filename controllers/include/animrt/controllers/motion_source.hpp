#pragma once
// A motion source turns time into joint targets. sample() runs inside the
// real-time cycle: it must not allocate, lock, log or do I/O.

#include <span>
#include <string>
#include <vector>

namespace animrt {

class MotionSource {
 public:
  virtual ~MotionSource() = default;

  // Robot joint indices this source drives, fixed after construction.
  virtual std::span<const int> driven_joints() const = 0;

  // Writes targets (rad) for the driven joints into `targets`, which is
  // indexed by robot joint index and has one entry per robot joint. Entries
  // of joints it does not drive are left untouched. `t` is seconds since the
  // motion started (t = 0 is the pose the start ramp goes to).
  virtual void sample(double t, std::span<double> targets) const = 0;
};

}  // namespace animrt
