#pragma once
// One simulated device on a CAN bus: it sees every frame its acceptance
// filters let through and answers with frames of its own. No I/O here;
// CanSimBus moves the frames.

#include <linux/can.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/clock.hpp"

namespace animrt::sim {

using FrameList = std::vector<can_frame>;

class CanNode {
 public:
  virtual ~CanNode() = default;
  virtual int device_id() const = 0;
  // The CAN ids this device listens to (exact matches).
  virtual std::vector<canid_t> listens_to() const = 0;
  // One received frame at `now`; answers appended to `out`.
  virtual void handle(const can_frame& frame, Nanos now, FrameList& out) = 0;
  // Time-driven output (heartbeats); called often.
  virtual void poll(Nanos now, FrameList& out) = 0;
  // Position of the joint (through the binding), for tests.
  virtual double joint_position(Nanos now) const = 0;

  // Fault injection: a silent device ignores every frame and sends nothing.
  void set_responding(bool responding) { responding_ = responding; }
  bool responding() const { return responding_; }
  // Non-zero bits: a device fault (the device reports it its own way); zero
  // clears the condition (a fault reset can then succeed).
  virtual void set_fault(std::uint8_t bits, Nanos now, FrameList& out) = 0;
  // Power cycle: the device restarts with its defaults and says so.
  virtual void reboot(Nanos now, FrameList& out) = 0;
  // A change to the device's health model at once (SimulatedBus::
  // inject_device_health); devices without one throw std::logic_error.
  virtual void inject_health(const SimHealthInjection&, Nanos, FrameList&) {
    throw std::logic_error("this simulated CAN device models no health");
  }
  // Whether the device's own guard against a dead host (heartbeat consumer,
  // CAN timeout) has fired and not yet been cleared.
  virtual bool guard_fired() const { return false; }

 private:
  bool responding_ = true;
};

}  // namespace animrt::sim
