#pragma once
// What a run reports at its end, as text for people and JSON for tools.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"

namespace animrt {

struct TimingSummary {
  std::uint64_t count = 0;
  double p50_s = 0.0;
  double p99_s = 0.0;
  double max_s = 0.0;
};

struct JointReport {
  std::string name;
  double rms_tracking_error_rad = 0.0;  // commanded (previous cycle) - measured
  double max_tracking_error_rad = 0.0;  // (a prismatic joint's errors are in m)
  bool prismatic = false;
};

struct DeviceReport {
  std::string bus;
  std::string joint;
  DeviceStatus status;
  HealthStats health{};  // readings over the run (NaN: not read)
};

struct BusReport {
  std::string name;
  TimingSummary io;  // read + write time of the bus per cycle (on its I/O thread)
  // Cycles in which the bus had not answered within the loop's read budget
  // (its joints kept their last measurement, the other buses went on).
  std::uint64_t late_cycles = 0;
};

// An IMU over the run: the readings the cycle took, the cycles that went
// on with an older one than due (late), the reports that never came
// (missing), and whether its silence faulted it.
struct ImuReport {
  std::string name;
  std::uint64_t readings = 0;
  std::uint64_t late_cycles = 0;
  std::uint64_t missing_reports = 0;
  bool faulted = false;
};

// What the physics behind simulated servos saw (`animrt run --physics`).
struct PhysicsReport {
  std::string model;
  double timestep_s = 0.0;
  double simulated_s = 0.0;          // physics time from the devices' start to the end
  double forward_m = 0.0;            // torso's +x displacement over that time (ramps included)
  double sideways_m = 0.0;           // torso's +y displacement
  double motion_s = 0.0;             // physics time of the motion proper (0: it never started)
  double motion_forward_m = 0.0;     // torso's +x displacement during the motion
  double average_speed_m_s = 0.0;    // motion_forward_m / motion_s
  int falls = 0;                     // upright -> fallen transitions (the gait fitness's criterion)
  double first_fall_s = -1.0;        // physics time of the first fall, -1 if none
  int lockstep_waits_timed_out = 0;  // a bus was late to a lockstep step: the run may not repeat
  // A gait's feet during the motion, counted as the gait fitness counts
  // them (-1: the motion is not a gait).
  double stride_length_m = -1.0;
  double duty_factor = -1.0;
};

enum class EndReason { duration, signal, fault };
const char* to_string(EndReason reason);

struct RunSummary {
  std::string robot;
  std::string backend;
  bool lockstep = false;
  double rate_hz = 0.0;
  EndReason end_reason = EndReason::duration;
  std::vector<std::string> faults;  // one line per faulted device
  // One line per health warning (a value past a warning limit; the run went on).
  std::vector<std::string> health_warnings;
  // One line per joint not at the stop pose when torque went off.
  std::vector<std::string> stop_warnings;
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;        // cycles that ended after the next deadline
  std::uint64_t skipped_cycles = 0;  // whole cycles left out after an overrun
  // Torque went off without the stop ramp finishing: why (empty otherwise).
  std::string torque_cut;
  double motion_time_s = 0.0;  // time spent playing the motion source
  TimingSummary period;        // between cycle starts
  TimingSummary jitter;        // cycle start - deadline
  TimingSummary busy;          // work per cycle (wake to end of writes)
  std::vector<BusReport> buses;
  std::vector<JointReport> joints;
  std::vector<DeviceReport> devices;
  std::vector<ImuReport> imus;
  bool sched_fifo = false;
  int sched_priority = 0;
  std::string sched_note;
  bool memory_locked = false;
  std::string mlock_note;
  std::vector<std::string> io_thread_notes;  // per bus I/O thread not at SCHED_FIFO: why
  // Per simulated devices' thread not at SCHED_FIFO (below the I/O threads): why.
  std::vector<std::string> device_thread_notes;
  std::string telemetry_file;
  std::uint64_t telemetry_records = 0;
  std::uint64_t telemetry_dropped = 0;
  // Records that could not be written, and why (strerror of the first
  // failed write; empty when none was lost).
  std::uint64_t telemetry_lost = 0;
  std::string telemetry_error;
  // The MCAP recording (--record): messages written, dropped (its rings
  // full), lost (not on disk) and why.
  std::string record_file;
  std::uint64_t record_messages = 0;
  std::uint64_t record_dropped = 0;
  std::uint64_t record_lost = 0;
  std::string record_error;
  std::optional<PhysicsReport> physics;  // set by whoever ran the physics

  // 0 for a clean run, 4 when a fault ended it, 5 when torque had to be cut
  // without the stop ramp (stop deadline, second stop request), 6 when the
  // figure's run was clean but its record is not (telemetry lost). What
  // happened to the figure comes first.
  int exit_code() const {
    if (end_reason == EndReason::fault) return 4;
    if (!torque_cut.empty()) return 5;
    const bool lost =
        telemetry_lost > 0 || !telemetry_error.empty() || record_lost > 0 || !record_error.empty();
    return lost ? 6 : 0;
  }
};

std::string format_summary(const RunSummary& summary);
nlohmann::json to_json(const RunSummary& summary);

}  // namespace animrt
