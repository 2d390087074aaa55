#pragma once
// Time sources. The loop and the simulated devices read time through Clock so
// that a lockstep run (ManualClock) is deterministic and independent of the
// machine's speed, while a real-time run uses CLOCK_MONOTONIC.

#include <atomic>
#include <cstdint>

namespace animrt {

using Nanos = std::int64_t;

class Clock {
 public:
  virtual ~Clock() = default;
  virtual Nanos now() const = 0;
};

// CLOCK_MONOTONIC.
class MonotonicClock final : public Clock {
 public:
  Nanos now() const override;
};

// Time that moves only when told to; shared between the loop and simulated
// devices in lockstep runs. Safe to read from other threads.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(Nanos start = 0) : now_(start) {}
  Nanos now() const override { return now_.load(std::memory_order_acquire); }
  void set(Nanos t) { now_.store(t, std::memory_order_release); }
  void advance(Nanos dt) { now_.fetch_add(dt, std::memory_order_acq_rel); }

 private:
  std::atomic<Nanos> now_;
};

inline double to_seconds(Nanos ns) { return static_cast<double>(ns) * 1e-9; }
inline Nanos from_seconds(double s) { return static_cast<Nanos>(s * 1e9 + (s >= 0 ? 0.5 : -0.5)); }

}  // namespace animrt
