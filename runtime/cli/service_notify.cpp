#include "service_notify.hpp"

#include <systemd/sd-daemon.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace animrt::cli {
namespace {

// Whether a watchdog is asked for (WATCHDOG_USEC, for this process), and its period.
std::uint64_t watchdog_usec() {
  std::uint64_t usec = 0;
  return sd_watchdog_enabled(0, &usec) > 0 ? usec : 0;
}

}  // namespace

ServiceNotifier::ServiceNotifier(const RunHeartbeat& heartbeat)
    : heartbeat_(heartbeat), watch_(watchdog_usec() > 0) {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  if (socket == nullptr || *socket == '\0') return;
  // Four looks per watchdog period: a ping at least every half period even
  // when a look falls just before a cycle completes. Without a watchdog,
  // often enough that READY=1 follows the start ramp closely.
  const std::uint64_t usec = watchdog_usec();
  const std::uint64_t every = usec > 0 ? usec / 4 : 100'000;
  interval_ = std::chrono::microseconds(std::clamp<std::uint64_t>(every, 10'000, 250'000));
  thread_ = std::thread([this] { loop(); });
}

ServiceNotifier::~ServiceNotifier() {
  if (!thread_.joinable()) return;
  quit_.store(true);
  thread_.join();
  look();
}

void ServiceNotifier::look() {
  for (const std::string& message : watch_.look(heartbeat_)) sd_notify(0, message.c_str());
}

void ServiceNotifier::loop() {
  while (!quit_.load()) {
    std::this_thread::sleep_for(interval_);
    look();
  }
}

}  // namespace animrt::cli
