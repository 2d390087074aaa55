#pragma once
// The two ends of a serial line to simulated devices in a lockstep run.
//
// A simulated device answers in no simulated time, and the run's clock holds
// still while the host waits for an answer. So once the device side has
// taken (and answered) every byte the host wrote, and the host has read
// every byte the device side wrote, nothing more will come until the host
// writes again: the host's wait can end at once, where on hardware it waits
// its timeout. A silent device then costs no wall time, and an answer is
// never counted missing because a loaded machine ran the device late.
//
// Both sides count bytes (lock-free, no allocation); the device side wakes
// the host through an eventfd each time it has taken a batch. The host's
// wall-clock wait is then only a guard (kGuard) against a device side that
// hangs. Hardware, and simulated devices on the wall clock, have no such
// line: their transports wait their timeouts. Modbus RTU requests follow the
// same line (firmware_bridge/src/modbus/modbus_requests.hpp); the virtual
// CAN bus, many endpoints to many, counts frames itself
// (VirtualCanBus::attach_lockstep_device).

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>

namespace animrt {

class LockstepLine {
 public:
  // The longest a host waits for a device side that neither answers nor
  // settles (a hung simulator); far beyond any answer on a loaded machine.
  static constexpr std::chrono::milliseconds kGuard{5000};

  LockstepLine();  // throws DeviceError when no eventfd can be made
  ~LockstepLine();
  LockstepLine(const LockstepLine&) = delete;
  LockstepLine& operator=(const LockstepLine&) = delete;

  // Host side (one thread: the bus's).
  void host_wrote(std::size_t bytes) { host_wrote_.fetch_add(bytes, std::memory_order_release); }
  void host_read(std::size_t bytes) { host_read_ += bytes; }
  // Nothing more will come until the host writes again.
  bool settled() const;
  // The device side has taken (and answered) every byte the host wrote, or
  // does not serve; its answers may still be unread (unread()).
  bool device_caught_up() const;
  // Bytes the device side wrote that the host has not read yet (in flight
  // in the pty, or queued); what a discard must read away.
  std::uint64_t unread() const;
  // Readable after the device side took bytes; clear_wake() empties it.
  int wake_fd() const { return wake_fd_; }
  void clear_wake() const;

  // Device side (one thread: the device's). wrote() before took() for the
  // bytes it answered.
  void device_wrote(std::size_t bytes) {
    device_wrote_.fetch_add(bytes, std::memory_order_release);
  }
  // The device has handled `bytes` more of what the host wrote, and written
  // every answer to them.
  void device_took(std::size_t bytes);
  // Whether the device side's thread runs: a stopped one takes nothing, so
  // the line is settled once its answers are read (a dead bus answers
  // nothing, at once). Off until the device side starts.
  void device_serving(bool serving);

 private:
  void wake();

  std::atomic<std::uint64_t> host_wrote_{0};
  std::atomic<std::uint64_t> device_took_{0};
  std::atomic<std::uint64_t> device_wrote_{0};
  std::atomic<bool> serving_{false};
  std::uint64_t host_read_ = 0;  // the host's thread only
  int wake_fd_ = -1;
};

}  // namespace animrt
