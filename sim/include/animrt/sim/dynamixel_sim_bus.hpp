#pragma once
// Simulated Dynamixel X-series servos of one bus behind a pseudo-terminal:
// any Protocol 2.0 client that opens endpoint() (raw 8N1) talks to them as it
// would to hardware. A background thread reads the pty master, decodes with
// the same codec the runtime uses, lets DynamixelFirmware answer, and writes
// the status packets back.
//
// Time: a packet takes effect at the Clock's time when the thread handles
// it. In lockstep (the Clock is a ManualClock) that is deterministic for a
// packet the client waits an answer for, since the clock holds still
// meanwhile; but a packet that never gets an answer (Sync Write, Bulk Write,
// broadcast Write...) may be handled only after the client has moved the
// clock on. So in lockstep such a packet takes effect at the time of the
// packet before it: the cycle it was sent in, when each cycle starts with an
// answered transaction (read, then write).
//
// A packet cut off by 5 ms of silence is dropped (as a servo's receive
// timeout does), so a truncated packet never swallows the next one.
//
// Baud rate: the pty starts at BusConfig::baud; each packet is heard only
// by the servos whose Baud Rate matches the rate the host has set on the
// pty when it arrives (ServoStartup::any_baud: by all).
//
// Wire time (SimBusSettings::wire_time): each answer is held back (real time)
// until the instruction's bytes, the servo's Return Delay Time and the
// answer's bytes would have passed at 10 bits per byte at BusConfig::baud.
// Each servo's slice of a Fast Sync/Bulk Read status packet counts as its
// answer here (the first one with the packet's header). The times are
// absolute (from the instruction's arrival, or from the end of the line's
// previous traffic if later), so a late wake-up never delays what follows;
// answers already due when the thread runs leave in one write, and the
// thread sleeps only until the next answer's time (one wake-up costs this
// machine more than a slice's wire time at 1 Mbaud).

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/thread_priority.hpp"
#include "animrt/sim/dynamixel_firmware.hpp"
#include "animrt/sim/serial_line.hpp"
#include "animrt/sim/servo_state_file.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt::sim {

struct DynamixelSimStats {
  std::uint64_t received_bytes = 0;        // bytes read from the line and handled
  std::uint64_t packets = 0;               // instruction packets handled (any id)
  std::uint64_t answers = 0;               // status packets sent
  std::uint64_t crc_errors = 0;            // packets dropped for a bad CRC (never answered)
  std::uint64_t malformed = 0;             // impossible length or bad stuffing
  std::uint64_t stray_bytes = 0;           // bytes outside any packet
  std::uint64_t dropped_bytes = 0;         // answer bytes the client never read (pty full)
  std::uint64_t partial_packet_bytes = 0;  // bytes of packets cut off by a silence
};

class DynamixelSimBus final : public SimulatedBus {
 public:
  // Opens the pty and builds the servos; throws DeviceError if no pty can be
  // opened and InputError for bad device ids. `physics` (optional, outlives
  // the bus) replaces the servos' motor model.
  // `startup`: factory settings and a state file (simulated_bus.hpp).
  DynamixelSimBus(const BusConfig& config, const Clock& clock, JointPhysics* physics = nullptr,
                  const ServoStartup& startup = {});
  ~DynamixelSimBus() override;
  DynamixelSimBus(const DynamixelSimBus&) = delete;
  DynamixelSimBus& operator=(const DynamixelSimBus&) = delete;

  const std::string& endpoint() const override { return endpoint_; }
  std::string describe() const override;
  void start() override;
  void stop() override;
  std::string raise_priority(int priority) override { return set_fifo_priority(thread_, priority); }
  // These take the id from the BusConfig; they throw std::out_of_range for
  // an id that is not on this bus.
  void set_device_responding(int device_id, bool responding) override;
  void set_device_hardware_error(int device_id, std::uint8_t error_bits) override;
  void inject_device_health(int device_id, const SimHealthInjection& change) override;
  double device_position(int device_id) const override;
  std::shared_ptr<LockstepLine> lockstep_line() const override { return line_; }
  // Late answers (see DynamixelServo::set_answer_delay) and the goal log.
  void set_device_answer_delay(int device_id, Nanos delay_ns, int answers = -1) override;
  void hand_move(int device_id, std::int32_t ticks) override;
  void hand_path(int device_id, const std::vector<std::int32_t>& ticks,
                 int reads_per_step) override;
  ServoReadout servo_readout(int device_id) const override;
  void set_device_plugged(std::size_t index, bool plugged) override;
  std::vector<GoalRecord> device_goal_log(int device_id) const;
  std::uint64_t device_goals_received(int device_id) const;

  DynamixelSimStats stats() const;

 private:
  void serve();
  void handle(const dxl::Packet& packet, Nanos arrival);
  void send(std::span<const std::uint8_t> bytes);
  void send_paced();  // answers_ at the times in due_
  Nanos wire_ns(std::size_t bytes) const;
  // The test aid of hand_path: under mutex_, after each packet.
  struct HandPath {
    int device_id = 0;
    std::vector<std::int32_t> ticks;
    std::size_t next = 1;             // ticks[next] comes after ...
    int reads_per_step = 1;           // ... this many reads at ticks[next - 1],
    std::uint64_t reads_at_step = 0;  // counted from the servo's position_reads() here
  };
  void follow_hand_paths(Nanos now);
  void close_fds();

  BusConfig config_;
  const Clock& clock_;
  std::string endpoint_;
  int master_ = -1;
  int slave_ = -1;  // held open so the master never sees a hangup between clients
  std::array<int, 2> wake_{-1, -1};

  mutable std::mutex mutex_;  // guards firmware_
  DynamixelFirmware firmware_;
  ServoStartupKeeper keeper_;         // under mutex_
  std::vector<HandPath> hand_paths_;  // under mutex_

  JointPhysics* physics_ = nullptr;
  int party_ = -1;  // lockstep with physics: this bus's party (JointPhysics::reach)

  // Serving thread only.
  bool any_baud_ = false;  // ServoStartup::any_baud
  bool lockstep_ = false;
  std::shared_ptr<LockstepLine> line_;  // lockstep only
  Nanos last_time_ = 0;                 // when the previous packet took effect
  dxl::Decoder decoder_;
  Answers answers_;
  Nanos bus_free_ = 0;      // wire time: when the emulated line is idle again
  std::vector<Nanos> due_;  // wire time: when each answer's last byte has arrived

  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> received_bytes_{0};
  std::atomic<std::uint64_t> packets_{0};
  std::atomic<std::uint64_t> answers_sent_{0};
  line::DecodeCounts decode_counts_;
  std::atomic<std::uint64_t> stray_bytes_{0};
  std::atomic<std::uint64_t> dropped_bytes_{0};
  std::atomic<std::uint64_t> dropped_partial_{0};
};

}  // namespace animrt::sim
