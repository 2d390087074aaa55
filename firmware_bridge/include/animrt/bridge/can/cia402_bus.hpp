#pragma once
// Master side of CANopen CiA 402 drives in cyclic synchronous position mode.
//
// configure(): per drive, expedited SDOs check the device type (402), set the
// heartbeat producer time, the mode (CSP) and the PDO mapping (RPDO1:
// controlword + target position; TPDO1: statusword + position actual, both
// synchronous; with `health`, TPDO1 adds the error code and TPDO2 carries
// current actual and DC link voltage), read the position, then NMT start.
// activate(): walks the controlword state machine to Operation Enabled
// (fault reset first if the drive is in Fault) with the target held at the
// actual position.
// Each cycle read() produces SYNC and collects every TPDO (one deadline);
// write() sends each RPDO, applied by the drives at the next SYNC.
// deactivate(): back down to Switch On Disabled, NMT pre-operational.
//
// Guard against a dead host (device_watchdog_ms, off when 0):
// arm_device_guard(), called once every bus of the run is active, writes
// each drive's abort connection option code (6007h) and its heartbeat
// consumer (1016h:01, the host's node id and the consumer time), and from
// then on read() produces the host's heartbeat (0x700 + host node id,
// operational) every host_heartbeat_ms on the bus's I/O thread.
// Heartbeats go out only while the loop cycles: a loop that hangs is as
// absent to a drive as a dead process, and both stop it. deactivate()
// clears the consumer (time 0) once the drive is down, so a clean end
// leaves no guard armed.
//
// Supervision: the heartbeat consumer marks a drive timed out when no
// heartbeat came for heartbeat_timeout_ms (bus time). A boot-up message in
// the middle of a run (the drive rebooted), an EMCY with a non-zero code, a
// statusword in Fault, or a drive that left Operation Enabled by itself make
// the device a hardware error, which the runtime's watchdog faults, ramping
// every other joint home.

#include <algorithm>
#include <chrono>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/can_transport.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/status_book.hpp"

namespace animrt {

class Cia402Bus final : public ActuatorBus {
 public:
  static constexpr int kTries = 3;              // per SDO
  static constexpr int kStateMachineSteps = 8;  // SYNC cycles to reach a state

  Cia402Bus(BusConfig config, std::unique_ptr<CanFrameTransport> transport);

  // The host's heartbeat period for a consumer time: a quarter of it, so
  // that a late cycle or two still leaves a heartbeat inside the window.
  static constexpr int host_heartbeat_ms(int device_watchdog_ms) {
    return std::max(1, device_watchdog_ms / 4);
  }
  // 1016h sub-index 1: bits 23-16 the producer's node id, 15-0 the time in ms.
  static std::uint32_t consumer_entry(int node_id, int ms) {
    return (static_cast<std::uint32_t>(node_id) << 16) | static_cast<std::uint32_t>(ms);
  }

  const BusConfig& config() const override { return config_; }
  void configure() override;
  void activate() override;
  // 6007h and the heartbeat consumer (1016h:01) on every drive, then the
  // host's heartbeats from every read on (device_watchdog_ms; none if off).
  void arm_device_guard() override;
  void deactivate() override;
  // Between activate() and deactivate(): one SYNC and the drives' TPDOs.
  // Otherwise (a limp figure being commissioned; drives disabled and
  // pre-operational) each drive's position actual by SDO, which allocates.
  void read(std::span<double> positions) override;
  void write(std::span<const double> positions) override;
  std::span<DeviceStatus> devices() override { return book_.devices(); }
  // With `health: on`, each SYNC's TPDO1 also carries the drive's Error
  // Code (603Fh), kept as DeviceStatus::reading's error bits, and a TPDO2
  // its current actual value (6078h, scaled by 6075h) and DC link voltage
  // (6079h).
  bool reads_health() const override { return options_.health; }
  // Commissioning, with the bus configured and not running: homing mode
  // (6060h = 6) with homing method 37 (35 where the drive knows only the
  // older number) or the joint's `homing` method, home offset (607Ch) =
  // `ticks`: drive `device` alone is enabled, a rising controlword bit 4
  // starts the homing, which on the current position moves nothing and
  // makes the position actual read `ticks` (a switch method, 17-30, first
  // moves the joint to its switch's edge, watched until its timeout_s);
  // statusword bits 12 and 10 (homing attained, target reached) end it,
  // bit 13 (homing error) fails it. Then the drive is disabled again, back
  // in cyclic synchronous position mode, and its position read back
  // (DeviceError when it is not `ticks`). While it is enabled the drive
  // watches the host's heartbeat as in a run (arm_device_guard(), this
  // drive only; cleared once it is disabled).
  std::int64_t set_home(std::size_t device, std::int64_t ticks) override;

  // What the runtime knows about each drive.
  struct DriveReport {
    cia402::State state = cia402::State::not_ready_to_switch_on;
    std::uint16_t statusword = 0;
    canopen::NmtState nmt = canopen::NmtState::pre_operational;
    canopen::Emcy last_emcy;  // code 0 if none
    std::uint64_t emcy_count = 0;
    std::uint64_t reboots = 0;  // boot-up messages after configure()
    std::uint64_t heartbeats = 0;
    bool heartbeat_lost = false;
  };
  const DriveReport& drive(std::size_t device) const { return drive_[device]; }
  const CanFrameTransport& transport() const { return *transport_; }
  // "EMCY 0x2310 (current), error register 0x03" or "" for one device.
  std::string fault_text(std::size_t device) const;

  // One SDO transaction (configuration; not for the cycle). Returns the
  // uploaded value; throws DeviceError naming the object and the abort code.
  std::uint32_t sdo_read(std::size_t device, std::uint16_t index, std::uint8_t sub);
  void sdo_write(std::size_t device, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                 std::uint8_t size);
  void nmt(canopen::NmtCommand command, std::size_t device);

 private:
  // Frames taken past a deadline before giving up (a flooding node).
  std::size_t frame_budget() const { return 64 + 8 * book_.size(); }
  // Sends `request` (retried on silence) and returns the answer's value.
  std::uint32_t sdo_exchange(std::size_t device, const can_frame& request, std::uint16_t index,
                             std::uint8_t sub, const std::string& what, canopen::SdoKind expected);
  // Sends SYNC and collects TPDOs of the drives in expect_ (one deadline).
  void sync_cycle();
  void read_limp();
  void handle(const can_frame& frame);
  void supervise();
  void send_rpdo(std::size_t device, std::uint16_t controlword, std::int32_t target);
  void map_health_tpdo(std::size_t device);
  // The host's heartbeat, when one is due (guard armed).
  void produce_heartbeat();
  static constexpr std::size_t kAllDrives = static_cast<std::size_t>(-1);
  // arm_device_guard() for every non-faulted drive or drive `only` alone;
  // throws DeviceError naming the write that failed (nothing deactivated).
  void arm_guard(std::size_t only);
  // Writes 1016h:01 = 0 on every drive or drive `only` (errors ignored) and
  // stops producing.
  void clear_device_guard(std::size_t only = kAllDrives);
  // Runs SYNC cycles until every non-faulted drive (or drive `only`) is in
  // `goal` (or steps run out); returns the drives that did not get there.
  std::string walk_to(cia402::State goal, std::size_t only = kAllDrives);
  // set_home()'s steps with the drive in homing mode, operational: "" or why it failed.
  std::string run_homing(std::size_t device);
  // 6098h (37, or 35 for the older profile, or the joint's `homing` method)
  // and, for a switch search, its speeds (6099h) and acceleration (609Ah).
  void write_homing_method(std::size_t device);
  int slot_of(canid_t cob, canid_t base) const;
  std::string prefix() const { return book_.prefix(); }
  std::string describe(std::size_t device) const { return book_.describe(device); }

  BusConfig config_;
  Cia402BusOptions options_;
  std::unique_ptr<CanFrameTransport> transport_;
  std::chrono::microseconds timeout_;
  Nanos heartbeat_timeout_ns_;

  StatusBook book_;
  std::vector<DriveReport> drive_;
  std::vector<std::int32_t> actual_counts_;
  std::vector<std::int32_t> target_counts_;
  std::vector<std::uint16_t> controlword_;
  std::vector<Nanos> last_heartbeat_;
  std::vector<std::uint8_t> expect_;       // TPDO awaited this cycle
  std::vector<std::uint8_t> hw_fault_;     // sticky hardware error (EMCY, reboot, fault state)
  std::vector<int> slot_of_node_;          // node id -> device index
  std::vector<double> min_rad_, max_rad_;  // goals that stay inside int32 counts
  std::vector<double> rated_current_a_;    // 6075h, for 6078h (health)
  std::vector<Cia402JointOptions> joint_options_;  // a temperature object, if named
  bool running_ = false;  // between activate() and deactivate(): OE expected
  bool fresh_ = false;
  bool producing_ = false;  // host heartbeats between arm_device_guard() and deactivate()
  Nanos host_heartbeat_ns_ = 0;
  Nanos next_host_heartbeat_ = 0;

  // SDO exchange in flight (configuration only).
  int sdo_slot_ = -1;
  bool sdo_done_ = false;
  canopen::Sdo sdo_answer_;
};

}  // namespace animrt
