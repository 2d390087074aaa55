#pragma once
// What a service manager (systemd's sd_notify protocol) is told about a
// run, decided from the loop's heartbeat by a thread beside the loop:
// READY=1 once the start ramp has ended and the motion plays, WATCHDOG=1
// only when cycles completed since the last look (or, after the loop, once
// the actuators were released, until the process exits), STOPPING=1 once
// the stop ramp has begun (or the run ended). The caller sends the messages.

#include <cstdint>
#include <string>
#include <vector>

#include "animrt/runtime/run_heartbeat.hpp"

namespace animrt {

class ServiceWatch {
 public:
  explicit ServiceWatch(bool watchdog) : watchdog_(watchdog) {}

  // The messages to send now, in order; called at the supervisor's pace
  // (for a watchdog, at least twice per watchdog period).
  std::vector<std::string> look(const RunHeartbeat& heartbeat);

  bool ready() const { return ready_; }
  bool stopping() const { return stopping_; }

 private:
  bool watchdog_;
  bool ready_ = false;
  bool stopping_ = false;
  std::uint64_t last_cycles_ = 0;
};

}  // namespace animrt
