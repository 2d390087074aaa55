#pragma once
// What a bus and each device on it need to know, as read from the robot
// config. Device units (ticks) exist only from here down.

#include <any>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animrt/bridge/device_health.hpp"
#include "animrt/core/error.hpp"

namespace animrt {

class LockstepLine;

// How a joint maps to one device on a bus.
struct ActuatorBinding {
  std::string joint;     // robot joint name
  int joint_index = -1;  // robot joint index
  int device_id = 0;     // bus address (Dynamixel id 0..252)
  double ticks_per_rad = 4096.0 / (2.0 * 3.14159265358979323846);  // native scale
  std::int32_t zero_ticks = 2048;                                  // ticks at 0 rad
  int direction = 1;                                               // +1 or -1
  // The joint's position limits (rad, or m for a prismatic joint), copied
  // from the robot file: every bus clamps its goals into them before they
  // reach the wire, whatever the layers above did. Unbounded by default.
  double min_position = -std::numeric_limits<double>::infinity();
  double max_position = std::numeric_limits<double>::infinity();
  // The device's own health limits (its actuator's health_limits key: the
  // keys given there over its bus's limits), if any.
  std::optional<HealthLimits> health_limits{};
  // Protocol-specific settings, owned by the protocol module that read them
  // (for example a register map or a pulse calibration).
  std::any options;

  std::int32_t to_ticks(double rad) const;
  // The goal a bus may send for `goal`: clamped into the joint's limits; a
  // NaN or infinite goal never reaches the wire, `held` (the previous goal)
  // is sent again instead.
  double safe_goal(double goal, double held) const;
  bool has_limits() const;
  double to_rad(std::int32_t ticks) const;
};

// A change to a simulated device's health at a time (the robot file's
// sim.inject list): seconds after the simulated devices start.
struct SimHealthInjection {
  enum class Kind : std::uint8_t { temperature, blocked, supply, hardware_error };
  int device_id = 0;
  double at_s = 0.0;
  Kind kind = Kind::temperature;
  double value = 0.0;  // deg C, 1/0 (blocked), V, or the error bits
};

// The simulated servos' health model (sim.health in the robot file): a
// first-order thermal model driven by the motor current, a supply that sags
// with it, and the current itself (idle, moving, or stalled against a block).
struct SimHealthSettings {
  double ambient_c = 36.0;         // where the temperature settles at rest
  double thermal_tau_s = 120.0;    // thermal time constant
  double heat_c_per_a2 = 20.0;     // steady rise above ambient per A^2 drawn
  double supply_v = 12.0;          // supply with no load
  double supply_ohm = 0.2;         // its source resistance: sag per A drawn
  double idle_current_a = 0.05;    // holding, not moving
  double current_per_rad_s = 0.1;  // added per rad/s of motion
  double stall_current_a = 1.4;    // drawn while the joint is blocked with torque on
  double overload_s = 1.0;         // stalled this long: the Overload error
  // Simulated Modbus and CiA 402 drives: their firmware's own overtemperature
  // trip; the output goes off until a fault reset below trip_c - 5 deg C.
  double trip_c = 80.0;
  std::vector<SimHealthInjection> inject{};
};

// A simulated CiA 402 drive's switch inputs (sim.switches), in degrees of
// the drive's encoder as it reads before any homing (counts / counts_per_rev
// * 360): a home switch active from home_from_deg to home_to_deg (either
// end open: to the end of travel), a negative limit switch active at and
// below negative_limit_deg, a positive one at and above positive_limit_deg.
struct SimDriveSwitches {
  int device_id = 0;
  double home_from_deg = -std::numeric_limits<double>::infinity();
  double home_to_deg = std::numeric_limits<double>::infinity();
  bool has_home = false;
  double negative_limit_deg = -std::numeric_limits<double>::infinity();
  double positive_limit_deg = std::numeric_limits<double>::infinity();
};

// Simulated-device settings of a bus (used only with --backend sim).
struct SimBusSettings {
  double time_constant_s = 0.02;  // first-order lag of each motor
  double max_speed_rad_s = 6.0;   // rate limit of each motor
  bool wire_time = false;         // emulate bytes on the wire at the baud rate
  int return_delay_us = 0;        // device's delay before answering
  int firmware_version = 0;       // Dynamixel: firmware the servos report (0: the default, 38)
  SimHealthSettings health{};
  std::vector<SimDriveSwitches> switches{};
};

struct BusConfig {
  std::string name;
  std::string protocol;  // a registered Protocol's name, e.g. "dynamixel2"
  std::string port;      // where the bus is: /dev/ttyUSB0, host:port, can0, ...
  int baud = 1'000'000;
  // The wait for ONE answer: from a request to its first answer, and from
  // each answer to the next when several devices answer one request (a
  // Sync Read). A request that N devices answer thus takes at most N times
  // this; a silent device costs it once.
  double timeout_s = 0.004;
  SimBusSettings sim;
  // The bus's own health limits (its health_limits key), in place of the
  // robot file's safety.health.
  std::optional<HealthLimits> health_limits{};
  std::vector<ActuatorBinding> actuators;  // devices on this bus, in config order
  std::any options;                        // protocol-specific, see ActuatorBinding::options
  Location where;                          // where the bus is declared
  // The loop period (s) the bus will run at, known before its keys are read
  // (defaults such as device_watchdog_ms depend on it); 0 when not known.
  double loop_period_s = 0.0;
  // Set by simulated devices on a lockstep clock (lockstep_line.hpp); the
  // bus's transport follows it. Empty on hardware.
  std::shared_ptr<LockstepLine> lockstep_line;
};

}  // namespace animrt
