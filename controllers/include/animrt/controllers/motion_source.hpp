#pragma once
// A motion source turns time into joint targets. sample() runs inside the
// real-time cycle: it must not allocate, lock, log or do I/O.

#include <span>
#include <string>
#include <vector>

namespace animrt {

// What a steered source is told while it plays: a herd's or a dashboard's
// command for a walking figure. Sources that cannot be steered ignore it.
struct MotionCommand {
  double speed_m_s = 0.0;   // forward speed
  double turn_rad_s = 0.0;  // turn rate, positive to the left
};

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

  // The newest steering command, handed over by the cycle before sample()
  // when one arrived (the cycle reads it from a lock-free mailbox). Same
  // rules as sample(): no allocation, lock, log or I/O.
  virtual void steer(const MotionCommand& /*command*/) {}
};

}  // namespace animrt
