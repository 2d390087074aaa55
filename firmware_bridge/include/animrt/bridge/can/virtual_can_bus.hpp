#pragma once
// An in-process CAN bus: every endpoint attached to it receives the frames
// the others send (never its own, as with SocketCAN's default loopback
// settings), through the same receive filters. Frames are the kernel's
// `can_frame` structures. Used by the fast tests and by `--backend sim`, so
// protocol code is exercised without kernel CAN.
//
// Delivery is immediate and ordered (one lock for the whole bus); each
// endpoint has a fixed queue (kQueueFrames) and counts an overflow when it is
// full. Faults can be injected: error frames, bus-off and its recovery.
// The bus has a clock (default CLOCK_MONOTONIC) that endpoints report as
// now(); a simulation sets its own so lockstep runs stay deterministic.

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "animrt/bridge/can/can_transport.hpp"
#include "animrt/core/clock.hpp"

namespace animrt {

class VirtualCanBus : public std::enable_shared_from_this<VirtualCanBus> {
 public:
  static constexpr std::size_t kQueueFrames = 1024;

  // The bus registered under `name`, created on first use; it lives as long
  // as someone holds it (an endpoint or the caller).
  static std::shared_ptr<VirtualCanBus> named(const std::string& name);

  explicit VirtualCanBus(std::string name);
  const std::string& name() const { return name_; }

  // Attaches a new endpoint (allocates its queue).
  std::unique_ptr<CanFrameTransport> attach();

  // Time source reported by the endpoints' now(); nullptr = CLOCK_MONOTONIC.
  // The clock must outlive the endpoints' use of it.
  void set_clock(const Clock* clock);

  // Fault injection. An error frame goes to every endpoint. set_bus_off(true):
  // an error frame with CAN_ERR_BUSOFF, then nothing is delivered and sends
  // fail until set_bus_off(false), which sends CAN_ERR_RESTARTED.
  void inject_error(const can_frame& error_frame);
  void set_bus_off(bool bus_off);

  std::uint64_t frames_delivered() const;

 private:
  friend class VirtualCanEndpoint;
  struct Queue;
  bool send_from(const Queue* sender, const can_frame& frame);
  void detach(Queue* queue);
  void deliver_locked(const Queue* sender, const can_frame& frame, bool error);
  Nanos now() const;

  std::string name_;
  mutable std::mutex mutex_;
  std::vector<Queue*> queues_;
  const Clock* clock_ = nullptr;
  bool bus_off_ = false;
  std::uint64_t delivered_ = 0;
};

}  // namespace animrt
