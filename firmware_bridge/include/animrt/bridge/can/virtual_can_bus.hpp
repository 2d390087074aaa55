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
//
// Lockstep: simulated devices on a lockstep clock attach through
// attach_lockstep_device() and say, after each frame and each poll, that
// they have served everything they took at the clock's time. The bus counts
// the frames it queued to them and the frames they took. While such a
// device is attached, every other endpoint's receive() follows them, as a
// serial LockstepLine does: it returns a frame as soon as one is queued, or
// nothing as soon as every serving device has taken, answered and polled at
// the clock's present time (nothing more will come until the host sends or
// the clock moves), whatever its timeout. A device thread that does not
// keep up (a loaded machine) then only makes the host wait; the wall clock
// is only a guard (LockstepLine::kGuard) against a hung one. Hardware, and
// devices on the wall clock, attach no such endpoint.

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "animrt/bridge/can/can_transport.hpp"
#include "animrt/core/clock.hpp"

namespace animrt {

// The simulated devices' end of a virtual bus on a lockstep clock.
class LockstepCanPort : public CanFrameTransport {
 public:
  // Whether the devices' thread runs: a stopped one takes nothing, so the
  // hosts do not wait for it.
  virtual void serving(bool on) = 0;
  // Every frame taken so far is handled and its answers sent, and the
  // devices' time-driven behaviour (heartbeats, guards) polled at `now`.
  virtual void served(Nanos now) = 0;
};

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
  // Attaches the devices' end of a lockstep simulation (see above).
  std::unique_ptr<LockstepCanPort> attach_lockstep_device();

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
  // Every serving lockstep device has served all it was sent at the clock's
  // time; wakes the ones that have not polled at it yet.
  bool settled_locked();
  void wake_followers_locked();
  Nanos now_locked() const;
  Nanos now() const;

  std::string name_;
  mutable std::mutex mutex_;
  std::vector<Queue*> queues_;
  const Clock* clock_ = nullptr;
  bool bus_off_ = false;
  std::uint64_t delivered_ = 0;
  std::size_t lockstep_devices_ = 0;  // attached; others follow them while > 0
};

}  // namespace animrt
