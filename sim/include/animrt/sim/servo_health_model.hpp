#pragma once
// What a simulated servo reports about itself: motor current, the supply
// voltage at its connector, its temperature, and the hardware error bits
// its firmware sets from them. Shared by the simulated serial servos; the
// servo feeds it its motion and torque state and reads the values back.
//
// Current: idle + per rad/s of motion, or the stall current while the joint
// is blocked with torque on. Temperature: first order towards ambient +
// heat_c_per_a2 * I^2 with thermal_tau_s. Supply: supply_v - supply_ohm * I.
// Error bits (Dynamixel Hardware Error Status layout): Input Voltage when the
// supply is outside the servo's voltage limits, Overheating above its
// temperature limit, Overload after overload_s stalled.
//
// Injections (SimHealthSettings::inject for this device, or the set_*
// calls) change the temperature, block the joint, or set the supply at a
// time; everything is integrated in closed form on the times given, so a
// lockstep run is deterministic.

#include <cstdint>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/clock.hpp"

namespace animrt::sim {

class ServoHealthModel {
 public:
  static constexpr std::uint8_t kInputVoltageBit = 0x01;
  static constexpr std::uint8_t kOverheatingBit = 0x04;
  static constexpr std::uint8_t kOverloadBit = 0x20;

  ServoHealthModel() = default;
  // `device_id` picks this device's injections; times count from `start`.
  ServoHealthModel(const SimHealthSettings& settings, int device_id, Nanos start);

  // On to `now` with the motor moving at `speed_rad_s` (torque on or off);
  // applies the injections due by then. Never goes back.
  void advance(Nanos now, double speed_rad_s, bool torque_on);

  const SimHealthSettings& settings() const { return settings_; }
  bool blocked() const { return blocked_; }
  double current_a() const { return current_a_; }
  double temperature_c() const { return temperature_c_; }
  double voltage_v() const { return supply_v_ - settings_.supply_ohm * current_a_; }
  // The error bits the firmware sets for these limits (deg C, V).
  std::uint8_t error_bits(double temperature_limit_c, double min_voltage_v,
                          double max_voltage_v) const;

  // Fault injection, at once (the next advance() starts from these).
  void set_blocked(bool blocked) { blocked_ = blocked; }
  void set_temperature(double celsius) { temperature_c_ = celsius; }
  void set_supply(double volts) { supply_v_ = volts; }

 private:
  void apply(const SimHealthInjection& injection);

  SimHealthSettings settings_;
  std::vector<SimHealthInjection> pending_;  // this device's, by time
  std::size_t next_ = 0;
  Nanos start_ = 0;
  Nanos time_ = 0;
  bool blocked_ = false;
  double current_a_ = 0.0;
  double temperature_c_ = 0.0;
  double supply_v_ = 0.0;
  double stalled_s_ = 0.0;
  std::uint8_t injected_bits_ = 0;

 public:
  // Error bits an injection set (hardware_error), for the servo to add.
  std::uint8_t injected_bits() const { return injected_bits_; }
};

}  // namespace animrt::sim
