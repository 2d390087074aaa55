#pragma once
// Master side of a Dynamixel Protocol 2.0 bus (X-series servos in position
// mode). configure() pings and reads every device; each cycle is then one
// read of the present positions (Fast Sync Read when the servos support it,
// else Sync Read) and one Sync Write of the goals.
//
// The transactions, the status book, the timeout (one timeout_s per answer:
// a Sync Read of N servos may take N of them, a silent servo costs one) and
// the ping rounds are the serial-servo core's (serial_servo/servo_link.hpp);
// this class adds what X-series servos need beyond it: the model check,
// Fast Sync Read, position limits in EEPROM and the Bus Watchdog.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/dynamixel/link_codec.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/bridge/goal_window.hpp"
#include "animrt/bridge/serial_servo/servo_positions.hpp"

namespace animrt {

class DynamixelBus final : public ActuatorBus {
 public:
  // Largest number of devices whose Sync Write fits one packet even after
  // worst-case byte stuffing.
  static constexpr std::size_t kMaxDevices = 150;
  // Attempts per device for the lifecycle transactions (not for the cycle).
  static constexpr int kTries = 3;
  // Largest position an X-series servo takes in position mode.
  static constexpr std::int32_t kXMaxTicks = 4095;
  // Largest Bus Watchdog (units of 20 ms).
  static constexpr std::uint8_t kMaxWatchdogUnits = 127;

  // Takes an open transport (tests inject one). Allocates every buffer the
  // cycle needs. Throws DeviceError for ids outside 0..252, duplicate ids, a
  // bad scale or direction, or more than kMaxDevices devices.
  DynamixelBus(BusConfig config, std::unique_ptr<ByteTransport> transport);

  const BusConfig& config() const override { return config_; }

  // Resets the counters, pings every device (kTries each, silent ones again
  // for kPingRounds rounds: ping_until_answered) and reads its
  // present position. Throws one DeviceError listing every device that failed,
  // or naming a device whose model number is not the configured `model`.
  // Decides the cycle's read: with `fast_read: auto`, Fast Sync Read when
  // every device's model and firmware (from its Ping answer) support it and
  // one Fast Sync Read of all of them succeeds; else Sync Read.
  // Before reading the positions, puts each servo in the Operating Mode its
  // joint needs (mode_warning()), torque off.
  // Then, for joints with limits, writes Min/Max Position Limit (52/48) from
  // them when the values read back differ (torque off first: EEPROM), so the
  // servo itself refuses goals outside the joint. A joint that rests outside
  // its limits (a jaw hanging open past closed) gets limits widened to its
  // measured position, with a warning (outside_warning()): torque on then
  // holds it where it is, and the goals lead it back inside (below).
  // A Bus Watchdog left set or fired (it reads 0xFF) by a run that died is
  // cleared (0), with a warning when it had fired (watchdog_warning()).
  void configure() override;
  // Per device: goal position = present position, then torque on. On failure
  // turns torque off again and throws DeviceError naming the device.
  void activate() override;
  // The Bus Watchdog (BusOptions::bus_watchdog, if not 0) on every servo at
  // once, by broadcast, then read back from each: from then on a servo stops
  // by itself when no instruction reaches it for that long. Armed one servo
  // at a time, the first would time out while the others are asked (12
  // servos at 57600 baud take longer than 60 ms).
  void arm_device_guard() override;
  // Bus Watchdog 0 (if set; not on faulted devices), then torque off, on
  // every device, and the Operating Mode a compliant hold changed put back;
  // best effort, never throws.
  void deactivate() override;
  // Current-based position mode (5) at `share` of the servo's Current Limit
  // (Goal Current), goal = present position, torque on. False for a model
  // without current sensing (it reports load: XL430, XC430, ...).
  bool activate_compliant(std::size_t device, double share) override;
  // A multi_turn joint's home: Homing Offset (EEPROM, torque off) set so
  // that where the joint rests reads `ticks`, taken from the shaft's angle
  // within its turn (a power-up counts from there), then Reboot, and the
  // present position read back (DeviceError when it is not `ticks`).
  // DeviceError for a joint that is not multi_turn.
  std::int64_t set_home(std::size_t device, std::int64_t ticks) override;

  // One Sync Read / Sync Write. Counters: `transactions` counts instruction
  // packets that expected an answer from the device (Sync Write expects none).
  // Neither throws: a line that is gone (adapter unplugged) shows as timeouts
  // of every device. Goals are clamped into the joint limits; NaN holds.
  // A joint that started outside its limits may also take goals between its
  // measured start and the limit, never farther out than a goal already
  // sent: the start ramp walks it in, and once inside it stays inside.
  // With a Bus Watchdog armed, a cycle that finds the line silent for more
  // than half its time (nothing sent, or no valid answer heard: the servos
  // may have stopped and locked their goals) first clears and re-arms it
  // with two broadcast Writes, so the figure goes on from where it stopped
  // (watchdog_rearms()).
  // With `health: packed` the cycle's read is of Indirect Data 1..10
  // (Present Position, Present Current, Present Input Voltage, Present
  // Temperature, Hardware Error Status, mapped by configure()); with
  // `round_robin` it reads positions as without, then the health registers
  // of one servo (the next in turn) in a Read of its own. Either fills
  // DeviceStatus::reading.
  void read(std::span<double> positions) override;
  void write(std::span<const double> positions) override;
  dxl::HealthRead health_read() const { return health_; }
  std::uint64_t watchdog_rearms() const { return watchdog_rearms_; }

  std::span<DeviceStatus> devices() override { return link_.book().devices(); }
  void switch_off(std::size_t device) override;
  bool reads_health() const override { return health_ != dxl::HealthRead::off; }

  // Where configure() looks for the USB adapter's latency timer (tests point
  // it at a fake tree); "/sys" by default.
  void set_sysfs_root(std::string root) { sysfs_root_ = std::move(root); }
  // The warning configure() printed (to stderr) about a latency timer above
  // 1 ms, with the command that fixes it; empty when there was none.
  const std::string& latency_warning() const { return latency_warning_; }
  // The warning configure() printed about joints resting outside their
  // limits (each with its angle and limits); empty when there was none.
  const std::string& outside_warning() const { return outside_warning_; }
  // The warning configure() printed about Bus Watchdogs that had fired;
  // empty when none had.
  const std::string& watchdog_warning() const { return watchdog_warning_; }
  // The warning configure() printed about servos it found in another
  // Operating Mode than their joints need (position, 3; extended position,
  // 4, for `multi_turn`) and set right; empty when all were right.
  const std::string& mode_warning() const { return mode_warning_; }

  // Whether the cycle's read is a Fast Sync Read (decided by configure()).
  bool fast_read_active() const { return fast_; }
  // Model number and firmware version of a device, from its Ping answer.
  std::uint16_t model_number(std::size_t device) const { return model_[device]; }
  std::uint8_t firmware_version(std::size_t device) const { return firmware_[device]; }

 private:
  using Answer = servo::Answer;

  Answer unicast(std::size_t device, std::size_t length, std::size_t data_length,
                 int tries = kTries, bool diagnostic = false) {
    return link_.unicast(device, length, data_length, tries, diagnostic);
  }
  // One Fast Sync Read of the link's slots [0, count): one status packet
  // with a slice per device, judged slice by slice.
  void transact_fast(std::size_t length, std::size_t count, std::size_t data_length);
  void choose_fast_read();
  void write_position_limits(std::size_t device);
  std::uint8_t needed_mode(std::size_t device) const;
  void set_operating_modes();
  void reboot_and_wait(std::size_t device);
  void clear_bus_watchdogs();
  void rearm_after_silence();
  // Bus Watchdog 0, then its time, to every servo in two broadcast writes.
  void broadcast_bus_watchdog();
  // Reads the hardware error register of devices whose alert just appeared.
  void read_pending_hardware_status();
  Answer write_register(std::size_t device, std::uint16_t address, std::uint32_t value,
                        std::uint16_t size, int tries);
  // Indirect Address 1..10 -> position and the health registers.
  void map_health_registers(std::size_t device);
  // The health registers in `data` (current, voltage, temperature, error).
  void take_health(std::size_t device, std::span<const std::uint8_t> data);
  void read_health_round_robin();
  std::uint16_t cycle_address() const;
  std::uint16_t cycle_length() const;

  // Why a lifecycle transaction failed; for `ok` the hardware error it carried.
  std::string failure(std::size_t device, Answer answer) const;
  std::string prefix() const { return link_.book().prefix(); }
  std::string describe(std::size_t device) const { return link_.book().describe(device); }

  BusConfig config_;
  servo::Link<dxl::LinkCodec> link_;
  servo::ServoPositions positions_;
  dxl::FastRead fast_mode_ = dxl::FastRead::automatic;
  bool fast_ = false;  // the cycle's read is a Fast Sync Read
  std::string sysfs_root_ = "/sys";
  std::string latency_warning_;
  std::string outside_warning_;
  std::string watchdog_warning_;
  std::string mode_warning_;
  std::uint8_t watchdog_units_ = 0;  // Bus Watchdog set before the first cycle; 0: none
  std::chrono::nanoseconds watchdog_time_{0};
  bool armed_ = false;  // between arm_device_guard() and deactivate()
  std::chrono::steady_clock::time_point last_answered_{};  // a valid answer to a cycle's read
  std::uint64_t watchdog_rearms_ = 0;
  std::vector<std::uint16_t> model_;  // from each device's Ping answer
  std::vector<std::uint8_t> firmware_;
  std::array<std::uint8_t, 2 * dxl::kMaxPacket> fast_rx_{};

  std::vector<std::uint8_t> sync_data_;
  dxl::HealthRead health_ = dxl::HealthRead::off;
  std::vector<double> current_unit_;       // per device, A per unit; 0: the model reports load
  std::size_t health_next_ = 0;            // round robin: the device whose turn is next
  std::vector<std::uint8_t> off_pending_;  // switch_off(): torque off at the next read
  // Per device, the Operating Mode before a compliant hold (kModeKept: none).
  static constexpr std::uint8_t kModeKept = 0xFF;
  std::vector<std::uint8_t> mode_before_;
  void restore_operating_mode(std::size_t device);
};

}  // namespace animrt
