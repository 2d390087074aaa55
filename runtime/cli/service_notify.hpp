#pragma once
// Telling systemd (a Type=notify unit with WatchdogSec) how a served figure
// is, from a thread beside the loop that reads the loop's heartbeat
// (ServiceWatch decides; this sends, with libsystemd's sd_notify). Nothing
// happens outside a service manager (no NOTIFY_SOCKET).

#include <atomic>
#include <chrono>
#include <thread>

#include "animrt/runtime/run_heartbeat.hpp"
#include "animrt/runtime/service_watch.hpp"

namespace animrt::cli {

class ServiceNotifier {
 public:
  explicit ServiceNotifier(const RunHeartbeat& heartbeat);
  // One last look (STOPPING=1 if the run ended without a stop ramp), then
  // the thread ends.
  ~ServiceNotifier();
  ServiceNotifier(const ServiceNotifier&) = delete;
  ServiceNotifier& operator=(const ServiceNotifier&) = delete;

 private:
  void look();
  void loop();

  const RunHeartbeat& heartbeat_;
  ServiceWatch watch_;
  std::chrono::microseconds interval_{0};
  std::atomic<bool> quit_{false};
  std::thread thread_;
};

}  // namespace animrt::cli
