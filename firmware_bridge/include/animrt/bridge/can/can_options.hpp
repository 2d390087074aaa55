#pragma once
// Protocol-specific settings of CAN buses and devices, as the protocol
// modules read them from the robot file (stored in BusConfig::options and
// ActuatorBinding::options). The simulated devices read them too.

#include <linux/can.h>

#include <any>
#include <string>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/can/mit_codec.hpp"

namespace animrt {

struct MitBusOptions {
  canid_t master_id = 0;  // CAN id the motors answer to
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

struct Cia402BusOptions {
  int heartbeat_ms = 50;           // producer time written to each drive (1017h)
  int heartbeat_timeout_ms = 150;  // consumer: a drive silent this long is timed out
  int sync_timeout_ms = 0;         // 0: BusConfig::timeout_s
};

// Options of a bus / binding of the given type; a default when absent.
template <class T>
T options_of(const std::any& any) {
  if (const T* p = std::any_cast<T>(&any)) return *p;
  return T{};
}

}  // namespace animrt
