#pragma once
// Simulated Feetech STS/SCS servos of one bus behind a pseudo-terminal: any
// client that opens endpoint() (raw 8N1) talks to them as to a servo board on
// a USB adapter. A background thread reads the pty master, decodes with the
// codec the runtime uses, lets FeetechBoard answer and writes the status
// packets back. A packet with a bad checksum is dropped silently, as a servo
// does.
//
// Time, as for the Dynamixel simulation: a packet takes effect at the
// Clock's time when it is handled; in lockstep a packet that gets no answer
// (Sync Write, broadcasts) takes effect at the time of the packet before it.
// A packet cut off by 5 ms of silence is dropped. With
// SimBusSettings::wire_time each answer is held back until the instruction's
// bytes, the servo's return delay and the answer's bytes would have passed
// at 10 bits per byte at BusConfig::baud.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <thread>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/thread_priority.hpp"
#include "animrt/sim/feetech/feetech_board.hpp"
#include "animrt/sim/maestro/pty_pair.hpp"
#include "animrt/sim/serial_line.hpp"
#include "animrt/sim/servo_state_file.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt::sim {

struct FeetechSimStats {
  std::uint64_t received_bytes = 0;  // bytes read from the line and handled
  std::uint64_t packets = 0;         // instruction packets handled
  std::uint64_t answers = 0;         // status packets sent
  std::uint64_t bad_checksums = 0;   // packets dropped, never answered
  std::uint64_t malformed = 0;
  std::uint64_t partial_packet_bytes = 0;
};

class FeetechSimBus final : public SimulatedBus {
 public:
  // Throws DeviceError if no pty can be opened, InputError for bad ids.
  // `startup`: factory settings and a state file (simulated_bus.hpp).
  FeetechSimBus(const BusConfig& config, ft::Series series, const Clock& clock,
                const ServoStartup& startup = {});
  ~FeetechSimBus() override;
  FeetechSimBus(const FeetechSimBus&) = delete;
  FeetechSimBus& operator=(const FeetechSimBus&) = delete;

  const std::string& endpoint() const override { return pty_.path(); }
  std::string describe() const override;
  void start() override;
  void stop() override;
  std::string raise_priority(int priority) override { return set_fifo_priority(thread_, priority); }
  // By the id of the BusConfig; std::out_of_range for an id not on the bus.
  void set_device_responding(int device_id, bool responding) override;
  // Sets the servo's fault bits (ft::error_bit): they appear in the error
  // byte of its status packets, and those in Unload Condition cut torque.
  void set_device_hardware_error(int device_id, std::uint8_t error_bits) override;
  void inject_device_health(int device_id, const SimHealthInjection& change) override;
  double device_position(int device_id) const override;
  std::shared_ptr<LockstepLine> lockstep_line() const override { return line_; }
  void hand_move(int device_id, std::int32_t ticks) override;
  ServoReadout servo_readout(int device_id) const override;
  void set_device_plugged(std::size_t index, bool plugged) override;
  std::uint64_t device_goals_received(int device_id) const;
  std::int32_t device_last_goal(int device_id) const;

  FeetechSimStats stats() const;

 private:
  void serve();
  void handle(const ft::Packet& packet, Nanos arrival);
  void send(std::span<const std::uint8_t> bytes);
  Nanos wire_ns(std::size_t bytes) const;
  FeetechServo& servo(int device_id);
  const FeetechServo& servo(int device_id) const;

  BusConfig config_;
  const Clock& clock_;
  PtyPair pty_;
  WakePipe wake_;

  mutable std::mutex mutex_;  // guards board_
  FeetechBoard board_;
  ServoStartupKeeper keeper_;  // under mutex_

  bool any_baud_ = false;  // ServoStartup::any_baud
  bool lockstep_ = false;
  std::shared_ptr<LockstepLine> line_;  // lockstep only
  Nanos last_time_ = 0;
  ft::Decoder decoder_;
  FeetechAnswers answers_;
  Nanos bus_free_ = 0;

  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> received_bytes_{0};
  std::atomic<std::uint64_t> packets_{0};
  std::atomic<std::uint64_t> answers_sent_{0};
  line::DecodeCounts decode_counts_;
  std::atomic<std::uint64_t> dropped_partial_{0};
};

}  // namespace animrt::sim
