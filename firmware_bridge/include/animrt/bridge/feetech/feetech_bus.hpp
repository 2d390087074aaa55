#pragma once
// Master side of a Feetech STS/SCS serial bus (servos in position mode).
// configure() pings and reads every servo; each cycle is then one read of the
// present positions (STS: one Sync Read; SCS, which has none: one Read per
// servo) and one Sync Write of the goal positions.
//
// The status packet's error byte holds the servo's fault bits (voltage,
// sensor, temperature, current, angle, overload); a non-zero byte counts as
// a hardware error and shows as DeviceHealth::hardware_error, which the
// runtime's watchdog faults. Its last value is kept in hardware_error_status.
//
// The transactions, the status book, the timeout (one timeout_s per answer)
// and the ping rounds are the serial-servo core's (serial_servo/servo_link.hpp).

#include <any>
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
#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/bridge/feetech/link_codec.hpp"
#include "animrt/bridge/goal_window.hpp"
#include "animrt/bridge/serial_servo/servo_positions.hpp"

namespace animrt {

namespace ft {
// Protocol-specific bus settings (BusConfig::options).
struct BusOptions {
  // Read Present Load, Voltage, Temperature, the status bits and (STS)
  // Present Current with the positions (bus key `health`).
  bool health = false;
};
inline BusOptions bus_options(const BusConfig& bus) {
  if (const auto* o = std::any_cast<BusOptions>(&bus.options)) return *o;
  return {};
}
}  // namespace ft

class FeetechBus final : public ActuatorBus {
 public:
  // Largest number of servos whose 2-byte goals fit one Sync Write (LEN is
  // one byte: 3 N + 4 <= 255).
  static constexpr std::size_t kMaxDevices = 83;
  // Attempts per servo for the lifecycle transactions (not for the cycle).
  static constexpr int kTries = 3;

  // Takes an open transport (tests inject one). Allocates every buffer the
  // cycle needs. Throws DeviceError for ids outside 0..253, duplicate ids, a
  // bad scale or direction, or more than kMaxDevices servos.
  FeetechBus(BusConfig config, ft::Series series, std::unique_ptr<ByteTransport> transport);

  const BusConfig& config() const override { return config_; }
  ft::Series series() const { return series_; }

  // Resets the counters, pings every servo (kTries each, silent ones again
  // for kPingRounds rounds: ping_until_answered) and reads its
  // present position. Throws one DeviceError listing every servo that failed.
  // Then, for joints with limits, writes Min/Max Angle Limit (9/11) from
  // them when the values read back differ (EEPROM unlocked for the write and
  // locked again), so the servo itself keeps its goals inside the joint. A
  // joint that rests outside its limits (a hanging jaw) gets limits widened
  // to where it is, with a warning (outside_warning()): the servo clamps its
  // goal into its angle limits, so torque on would otherwise snap it to the
  // nearest limit. Its goals then lead from where it rests to its limits and
  // never back out past a goal already sent.
  void configure() override;
  // Per servo: goal position = present position, then torque on. On failure
  // (or a servo reporting a fault) turns torque off again and throws.
  void activate() override;
  // Torque off on every servo, and the Torque Limit a compliant hold
  // lowered put back; best effort, never throws.
  void deactivate() override;
  // STS: Torque Limit (48) at `share` of the servo's maximum torque, goal =
  // present position, torque on. False on the SCS series.
  bool activate_compliant(std::size_t device, double share) override;

  // One cycle; neither throws nor allocates. read() waits at most one
  // timeout per servo (one for each answer of the Sync Read, STS; one for
  // each Read, SCS). Goals are clamped into the
  // joint limits and the servo's position range; NaN holds the last goal.
  void read(std::span<double> positions) override;
  void write(std::span<const double> positions) override;

  std::span<DeviceStatus> devices() override { return link_.book().devices(); }
  // With `health: on` the cycle's read covers Present Position to Present
  // Current (56..70, 15 bytes, STS) or to Present Temperature (56..63, SCS)
  // and fills DeviceStatus::reading: STS current in 6.5 mA units, supply
  // voltage, temperature and the status bits (65; SCS: the status packet's
  // error byte).
  bool reads_health() const override { return health_; }
  // The last configure()'s warning about joints resting outside their
  // limits, empty when none did.
  const std::string& outside_warning() const { return outside_warning_; }

 private:
  using Answer = servo::Answer;

  Answer unicast(std::size_t device, std::size_t length, std::size_t data_length,
                 int tries = kTries) {
    return link_.unicast(device, length, data_length, tries);
  }
  Answer write_byte(std::size_t device, std::uint8_t address, std::uint8_t value);
  Answer write_goal(std::size_t device, std::int32_t ticks);
  void write_angle_limits(std::size_t device);
  void read_positions(std::size_t count);
  std::int32_t to_position(std::uint16_t raw) const;
  std::uint16_t from_position(std::int32_t ticks) const;

  std::string failure(std::size_t device, Answer answer) const;
  std::string prefix() const { return link_.book().prefix(); }
  std::string describe(std::size_t device) const { return link_.book().describe(device); }

  BusConfig config_;
  ft::Series series_;
  servo::Link<ft::LinkCodec> link_;
  std::int32_t min_ticks_, max_ticks_;  // position range of the series

  servo::ServoPositions positions_;
  std::string outside_warning_;
  std::vector<std::uint8_t> sync_data_;
  bool health_ = false;
  // Per device, the Torque Limit before a compliant hold (0: unchanged).
  std::vector<std::uint16_t> limit_before_;
  Answer write_torque_limit(std::size_t device, std::uint16_t limit);
  void take_health(std::size_t device, std::span<const std::uint8_t> data);
};

}  // namespace animrt
