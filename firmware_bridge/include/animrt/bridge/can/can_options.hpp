#pragma once
// Protocol-specific settings of CAN buses and devices, as the protocol
// modules read them from the robot file (stored in BusConfig::options and
// ActuatorBinding::options). The simulated devices read them too.

#include <linux/can.h>

#include <any>
#include <cstdint>
#include <string>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/can/mit_codec.hpp"

namespace animrt {

struct MitBusOptions {
  canid_t master_id = 0;  // CAN id the motors answer to
  // Each motor's CAN timeout as set in its setup menu (device_watchdog_ms;
  // not settable over CAN): limp after this long without a frame. 0: none.
  int device_watchdog_ms = 0;
};

struct MitMotorOptions {
  std::string model;      // e.g. "ak80-9"
  mit::Ranges ranges;     // the model's, or overridden in the config
  double kp = 0.0;        // N m / rad
  double kd = 0.0;        // N m s / rad
  double zero_rad = 0.0;  // motor position at joint angle 0
  // Joint limits in motor radians (min <= max): every command is clamped
  // here before packing.
  double min_motor_rad = 0.0, max_motor_rad = 0.0;

  // Joint angle -> motor angle and back (direction from the binding).
  double to_motor(double joint_rad, int direction) const {
    return zero_rad + direction * joint_rad;
  }
  double to_joint(double motor_rad, int direction) const {
    return direction * (motor_rad - zero_rad);
  }
};

// What a CiA 402 drive does when its heartbeat consumer misses the host
// (object 6007h, abort connection option code).
enum class AbortConnection : std::int16_t {
  fault = 1,            // fault signal: the drive goes to Fault
  disable_voltage = 2,  // disable voltage command: Switch On Disabled
  quick_stop = 3,       // quick stop command: stops on the quick stop ramp
};
const char* to_string(AbortConnection action);

struct Cia402BusOptions {
  // Two directions of watching, one key each:
  // - the host watches the drives: each drive produces heartbeats every
  //   heartbeat_ms (1017h); one silent for heartbeat_timeout_ms is timed out.
  int heartbeat_ms = 50;
  int heartbeat_timeout_ms = 150;
  // - the drives watch the host (device_watchdog_ms, 1016h; 0: off): the
  //   host produces heartbeats as node host_node_id, and a drive that misses
  //   them for device_watchdog_ms does abort_connection (6007h).
  int device_watchdog_ms = 0;
  int host_node_id = 127;
  AbortConnection abort_connection = AbortConnection::quick_stop;
  int sync_timeout_ms = 0;  // 0: BusConfig::timeout_s
  // Error Code (603Fh) mapped into TPDO1 after statusword and position
  // actual (8 bytes, the same frame each SYNC): bus key `health`.
  bool health = false;
};

// A drive's temperature in a manufacturer object (CiA 402 defines none):
// actuator key `temperature: {object: "0x2022:0x01", type: int16, scale: 0.1}`,
// mapped at configure into TPDO2 after the current and DC link voltage
// (so 8 or 16 bits: the PDO holds 64).
struct Cia402Temperature {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  int bits = 16;
  bool is_signed = true;
  double scale = 1.0;  // deg C per count

  double decode(std::uint32_t raw) const {
    const std::uint32_t mask = bits == 8 ? 0xFFu : 0xFFFFu;
    raw &= mask;
    const double v = is_signed && (raw & (mask ^ (mask >> 1)))
                         ? static_cast<double>(raw) - static_cast<double>(mask) - 1.0
                         : static_cast<double>(raw);
    return v * scale;
  }
};

// How calibrate homes a drive: actuator key `homing: {method, speed_dps,
// zero_speed_dps, acceleration_dps2, timeout_s}`. Methods 35/37 home on the
// present position and move nothing; 17-30 search a limit or home switch at
// 6099h:01 (then creep at 6099h:02) with 609Ah, in counts per second.
struct Cia402Homing {
  std::int8_t method = 37;
  std::uint32_t switch_speed = 0;  // 6099h:01, counts/s
  std::uint32_t zero_speed = 0;    // 6099h:02, counts/s
  std::uint32_t acceleration = 0;  // 609Ah, counts/s^2; 0: the drive's own
  double timeout_s = 30.0;         // the host gives up (and halts the search)
  bool on_switches() const { return method >= 17 && method <= 30; }
};

struct Cia402JointOptions {
  bool has_temperature = false;
  Cia402Temperature temperature;
  Cia402Homing homing;
};

// Options of a bus / binding of the given type; a default when absent.
template <class T>
T options_of(const std::any& any) {
  if (const T* p = std::any_cast<T>(&any)) return *p;
  return T{};
}

}  // namespace animrt
