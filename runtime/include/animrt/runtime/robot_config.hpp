#pragma once
// The robot file: joints, buses, actuator bindings, loop rate, safety and the
// motion source. Loading validates everything; nothing moves until it passes.

#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/imu/imu_config.hpp"
#include "animrt/controllers/head/head_source.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {

struct SafetyConfig {
  double watchdog_timeout_s = 0.1;  // a device silent this long is faulted
  double start_ramp_s = 2.0;        // measured pose -> first pose of the motion
  double stop_ramp_s = 2.0;         // current pose -> home
  // A start ramp that would need longer than this (the measured pose far from
  // the first pose, slow limits) is refused before torque goes on.
  double start_ramp_max_s = 20.0;
  // From a stop request (signal, duration, fault) to torque off, at most:
  // the stop ramp is cut short and torque switched off when it runs over.
  double stop_deadline_s = 6.0;
  // Following-error watch: a joint whose RMS error (measured against the
  // command it was sent) over the last window exceeds this is faulted.
  double following_error_rad = 0.2617993877991494;  // 15 deg (revolute joints)
  double following_error_m = 0.015;                 // prismatic joints
  double following_error_window_s = 0.5;
  // Device health limits (safety.health); a bus may have its own.
  HealthLimits health{};
  // Tilt watch (needs an IMU): the trunk's roll or pitch beyond
  // tilt_limit_rad for tilt_time_s ends the motion (0 = off). A figure that
  // is falling or on its side must not ramp home (the legs would push on the
  // floor and against the fall): on_tilt `hold` keeps every joint where it
  // is for tilt_hold_s, then torque goes off as at every end of a run;
  // `torque_off` lets go at once.
  double tilt_limit_rad = 0.0;
  double tilt_time_s = 0.2;
  enum class OnTilt { hold, torque_off } on_tilt = OnTilt::hold;
  double tilt_hold_s = 1.0;
};

struct MotionConfig {
  std::string type;  // "gait", "show", "head" or "layers"
  std::string file;  // resolved against the robot file's folder
  Location where;
  std::string key;  // dotted key of `where`, e.g. "motion.file" or "motion.layers[1].file"
  std::shared_ptr<const head::HeadMotionConfig> head;  // type "head" (parsed in controllers/head)
  std::vector<MotionConfig> layers;  // type "layers": applied in order, later layers win
};

// Real time: how long after its deadline a cycle waits for the buses'
// reads, as a fraction of the period. A bus that has not answered by then
// keeps its last measurement this cycle (a late cycle).
inline constexpr double kReadBudgetFraction = 0.6;
// What a read transaction costs beyond its bits on the wire (the host's
// scheduling, the adapter's USB frames, the servos' turnaround), at the
// 99th percentile since every read over the budget is a late cycle: the
// pony's 16-servo Sync Read at 1 Mbaud, 2.70 ms on the wire, took 3.12 ms
// at p99 (2.86 ms p50) on an idle test machine (docs/results/bus_read_budget.md).
inline constexpr double kReadOverheadS = 420e-6;

struct RobotConfig {
  std::string file;
  std::string name;
  double rate_hz = 200.0;
  SafetyConfig safety;
  std::vector<JointSpec> joints;
  Location joints_where;         // of the `joints` key (a joint another file needs is named there)
  std::vector<BusConfig> buses;  // each with its actuators (joint_index filled in)
  std::vector<ImuConfig> imus;   // the first is the trunk's
  MotionConfig motion;
  // Optional MJCF model of the figure (the dashboard draws it): resolved
  // against the robot file's folder; empty when the file names none.
  std::string model;
  Location model_where;  // of the `model` key's value
  // Per joint (or empty): why the joint may not keep up with its motion, as
  // found on load (robot_loader.hpp), for the following-error fault's hint.
  std::vector<std::string> lag_notes;
};

// Throws InputError (file, line, column, key) on the first problem found.
RobotConfig load_robot_config(const std::string& path);

}  // namespace animrt
