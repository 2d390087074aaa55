#pragma once
// CAN frames to and from one interface. The same `can_frame` structures
// travel over SocketCAN (a raw socket on can0, vcan0, ...) and over the
// in-process virtual bus that the fast tests and `--backend sim` use, so the
// protocol code above never knows which one it talks to.

#include <linux/can.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "animrt/core/clock.hpp"

namespace animrt {

// Error frames and transport trouble, counted since the transport opened.
struct CanErrorCounters {
  std::uint64_t error_frames = 0;         // every CAN_ERR_FLAG frame received
  std::uint64_t bus_off = 0;              // CAN_ERR_BUSOFF
  std::uint64_t error_passive = 0;        // controller reached error passive (rx or tx)
  std::uint64_t error_warning = 0;        // controller reached the warning level
  std::uint64_t arbitration_lost = 0;     // CAN_ERR_LOSTARB
  std::uint64_t protocol_violations = 0;  // CAN_ERR_PROT (bit, form, stuff errors)
  std::uint64_t no_ack = 0;               // CAN_ERR_ACK: nobody acknowledged
  std::uint64_t restarts = 0;             // CAN_ERR_RESTARTED (bus-off recovery)
  std::uint64_t rx_overflows = 0;         // controller or queue overflow: frames lost
  std::uint64_t tx_dropped = 0;           // send() refused (queue full, interface down)
};

class CanFrameTransport {
 public:
  virtual ~CanFrameTransport() = default;
  virtual const std::string& interface() const = 0;

  // Receive filters: a frame is delivered when (id & mask) == (filter & mask)
  // for any filter (SocketCAN CAN_RAW_FILTER semantics). Error frames are
  // always requested and consumed by the transport (counted, never returned).
  // Call before the cycle starts: it may allocate.
  virtual void set_filters(std::span<const can_filter> filters) = 0;

  // Queues one frame; never blocks. False when the frame could not be queued
  // (counted in tx_dropped): a full queue, or an interface that is bus-off.
  virtual bool send(const can_frame& frame) = 0;
  // Next frame that passed the filters, waiting at most `timeout` (zero: only
  // what is already there). False on timeout. Never allocates.
  virtual bool receive(can_frame& frame, std::chrono::microseconds timeout) = 0;

  virtual const CanErrorCounters& errors() const = 0;
  // Since the last bus-off error frame and until a restart: nothing gets through.
  virtual bool bus_off() const = 0;
  // Time of the bus: CLOCK_MONOTONIC on SocketCAN; the simulation's clock on
  // the virtual bus (so heartbeat supervision is deterministic in lockstep).
  virtual Nanos now() const = 0;
};

// "virtual:NAME" opens an endpoint on the in-process virtual bus NAME (see
// VirtualCanBus); anything else is a SocketCAN interface name. Throws
// DeviceError naming the interface and the reason.
std::unique_ptr<CanFrameTransport> open_can(const std::string& port);

struct BusConfig;
// open_can for a CAN bus of the robot file; the error names the bus.
std::unique_ptr<CanFrameTransport> open_bus_can(const BusConfig& bus);

inline constexpr std::string_view kVirtualCanPrefix = "virtual:";

// Counts one error frame into `counters`; returns +1 if it reports bus-off,
// -1 if it reports a restart (bus-off recovery), 0 otherwise.
int count_error_frame(const can_frame& frame, CanErrorCounters& counters);

// "3 error frames (1 bus-off, 2 error passive)" or "" when nothing happened.
std::string describe_errors(const CanErrorCounters& counters);

}  // namespace animrt
