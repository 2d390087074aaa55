#pragma once
// The loop's pulse, for a supervisor beside it (a service manager's
// watchdog): the cycle stores its count and phase after every cycle it
// completes, with two atomic stores (no syscall, lock or allocation), and a
// thread outside the cycle reads them. A loop that stalls stops the count,
// however alive the rest of the process is.

#include <atomic>
#include <cstdint>

#include "animrt/runtime/cycle.hpp"

namespace animrt {

class RunHeartbeat {
 public:
  enum class Stage : std::uint8_t { bring_up, start_ramp, motion, stop_ramp, ended };

  // --- the cycle's side ---
  void beat(Phase phase) {
    const Stage stage = phase == Phase::start_ramp  ? Stage::start_ramp
                        : phase == Phase::motion    ? Stage::motion
                        : phase == Phase::stop_ramp ? Stage::stop_ramp
                                                    : Stage::ended;
    if (stage == Stage::motion) moved_.store(true, std::memory_order_relaxed);
    stage_.store(stage, std::memory_order_relaxed);
    cycles_.fetch_add(1, std::memory_order_release);
  }
  // After the last cycle, whatever ended the run.
  void end() { stage_.store(Stage::ended, std::memory_order_release); }
  // After end(), once every actuator was released (torque off): whatever
  // the process does until it exits cannot move the figure.
  void released() { safe_.store(true, std::memory_order_release); }

  // --- the reader's side ---
  std::uint64_t cycles() const { return cycles_.load(std::memory_order_acquire); }
  Stage stage() const { return stage_.load(std::memory_order_acquire); }
  // The start ramp has ended and the motion has played.
  bool moved() const { return moved_.load(std::memory_order_acquire); }
  bool safe() const { return safe_.load(std::memory_order_acquire); }

 private:
  std::atomic<std::uint64_t> cycles_{0};
  std::atomic<Stage> stage_{Stage::bring_up};
  std::atomic<bool> moved_{false};
  std::atomic<bool> safe_{false};
};

}  // namespace animrt
