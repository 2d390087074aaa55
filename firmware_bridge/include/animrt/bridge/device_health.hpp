#pragma once
// What a device says about itself besides its position: temperature,
// current, supply voltage and its own error bits, each as the device
// reported it in SI units (NaN: this device or protocol does not report
// it, or the bus does not read it). One record per device, kept in its
// DeviceStatus by the bus that reads it, so every protocol hands the
// runtime the same thing.

#include <cmath>
#include <cstdint>
#include <limits>

namespace animrt {

struct HealthReading {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  double temperature_c = kNone;
  double current_a = kNone;  // magnitude of the motor current (or torque-producing current)
  double voltage_v = kNone;  // the device's supply input
  double torque_nm = kNone;  // magnitude of the torque the device reports (MIT replies)
  // The device's own fault register (Dynamixel Hardware Error Status,
  // Feetech status bits, CiA 402 Error Code), as read;
  // meaningful only when has_error_bits.
  std::uint32_t error_bits = 0;
  bool has_error_bits = false;
  // When it was read (steady clock, ns since its epoch); -1: never.
  std::int64_t read_ns = -1;
  // Reads so far: a reader tells a fresh record from one it has seen.
  std::uint64_t reads = 0;

  bool any() const { return read_ns >= 0; }
};

// Per device, over the run: what its health readings were (NaN: never read).
struct HealthStats {
  double min_temperature_c = HealthReading::kNone;
  double max_temperature_c = HealthReading::kNone;
  double peak_current_a = HealthReading::kNone;
  double min_voltage_v = HealthReading::kNone;
  double peak_torque_nm = HealthReading::kNone;
  std::uint64_t readings = 0;
  std::uint64_t warnings = 0;
};

// What the runtime does with the readings (the robot file's safety.health,
// or a bus's health_limits). A limit that is NaN is not watched.
struct HealthLimits {
  static constexpr double kOff = std::numeric_limits<double>::quiet_NaN();
  double temperature_warn_c = kOff;
  double temperature_fault_c = kOff;
  double voltage_warn_v = kOff;   // below this: a warning
  double voltage_fault_v = kOff;  // below this: a fault (undervoltage)
  // Stall: current above stall_current_a for stall_time_s while the joint
  // is more than stall_error_rad (m for a prismatic joint) from its command.
  double stall_current_a = kOff;
  double stall_time_s = 0.2;
  double stall_error_rad = 0.03490658503988659;  // 2 deg
  enum class Bits : std::uint8_t { fault, warn, ignore };
  Bits error_bits = Bits::fault;  // the device's own error bits, non-zero

  bool any() const {
    return !std::isnan(temperature_warn_c) || !std::isnan(temperature_fault_c) ||
           !std::isnan(voltage_warn_v) || !std::isnan(voltage_fault_v) ||
           !std::isnan(stall_current_a);
  }
};

}  // namespace animrt
