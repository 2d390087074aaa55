#pragma once
// A show's time as its sound output hears it. The sound track's player
// publishes, after each block it writes, the show time being heard and the
// run-clock time it read that at; the cycle reads it (never waiting) and
// interpolates to its own time, so a show with a sound track runs on the
// sound device's clock (its crystal), not the loop's. A SoundFollower turns
// the gap between the two into a small change of the show's speed, so the
// motion converges on the sound without a jump.

#include <atomic>
#include <cstdint>

#include "animrt/core/clock.hpp"

namespace animrt {

class SoundClock {
 public:
  struct Reading {
    double show_s = 0.0;  // show time heard at `stamp` (not wrapped)
    Nanos stamp = 0;      // on the run's clock
    bool playing = false;
    std::uint64_t commands = 0;  // show commands the player had taken by then
  };

  // The player's thread.
  void publish(const Reading& r) {
    const std::uint64_t seq = seq_.load(std::memory_order_relaxed);
    seq_.store(seq + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    show_s_.store(r.show_s, std::memory_order_relaxed);
    stamp_.store(r.stamp, std::memory_order_relaxed);
    playing_.store(r.playing, std::memory_order_relaxed);
    commands_.store(r.commands, std::memory_order_relaxed);
    seq_.store(seq + 2, std::memory_order_release);
  }

  // The cycle: false when nothing was published yet, or a publication was
  // under way each time it looked (it tries a few times, never waits).
  bool read(Reading& out) const {
    for (int attempt = 0; attempt < 4; ++attempt) {
      const std::uint64_t before = seq_.load(std::memory_order_acquire);
      if (before == 0) return false;
      if (before & 1u) continue;
      out.show_s = show_s_.load(std::memory_order_relaxed);
      out.stamp = stamp_.load(std::memory_order_relaxed);
      out.playing = playing_.load(std::memory_order_relaxed);
      out.commands = commands_.load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == before) return true;
    }
    return false;
  }

 private:
  std::atomic<std::uint64_t> seq_{0};  // odd while a publication is under way
  std::atomic<double> show_s_{0.0};
  std::atomic<Nanos> stamp_{0};
  std::atomic<bool> playing_{false};
  std::atomic<std::uint64_t> commands_{0};
};

// The motion's side: how much faster or slower than the loop's clock the
// show should run right now to close the gap to the sound. A
// proportional-integral loop (critically damped, time constant 1 s) on the
// gap, its speed change bounded, so a crystal's steady drift is followed
// with no lasting gap and the motion never jumps. Plain arithmetic.
class SoundFollower {
 public:
  // The largest change of the show's speed the follower asks for.
  static constexpr double kMaxRate = 0.05;
  // Readings older than this (the player stalled or ended) are not followed.
  static constexpr double kStaleS = 0.2;
  // A gap larger than this is the player's to close (it re-syncs the sound).
  static constexpr double kMaxGapS = 0.25;

  // The show time to add over `dt` seconds of loop time, given the gap
  // (sound minus motion, seconds) at its end; `valid` false when the sound
  // cannot be followed now (the integral is kept for when it can).
  double correction(double gap_s, double dt, bool valid) {
    if (!valid || !(dt > 0.0) || !(gap_s < kMaxGapS && gap_s > -kMaxGapS)) return 0.0;
    integral_ = clamp(integral_ + kKi * gap_s * dt);
    return clamp(integral_ + kKp * gap_s) * dt;
  }
  void reset() { integral_ = 0.0; }

 private:
  static constexpr double kKp = 2.0;  // 1/s
  static constexpr double kKi = 1.0;  // 1/s^2
  static double clamp(double r) { return r > kMaxRate ? kMaxRate : r < -kMaxRate ? -kMaxRate : r; }
  double integral_ = 0.0;
};

}  // namespace animrt
