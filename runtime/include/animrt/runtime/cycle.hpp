#pragma once
// One cycle of the run as a plain function: step(model, motion, state,
// inputs) maps the cycle state, this cycle's I/O results and the time to the
// commands for the buses and the events of the cycle. No threads, no clock,
// no I/O: the runner and its run loop are the shell around it, and every
// edge of the safety path (a late bus, a NaN from the motion, a silent
// device, a joint that does not follow, a stop that runs over) is a
// deterministic unit test.
//
// step() runs in named stages (cycle.cpp): take the controls, take the
// measurements, watch the devices, watch the following error, cut torque
// if asked, change phase, take manual targets, control a show, sample the
// targets, filter and route them to the buses, settle the stop.
//
// Everything step() touches is allocated when the CycleState is built;
// step() itself never allocates.

#include <cstdint>
#include <span>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/imu.hpp"
#include "animrt/runtime/pose_ramp.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/runtime/run_controls.hpp"
#include "animrt/runtime/safety_filter.hpp"

namespace animrt {

enum class Phase { start_ramp, motion, stop_ramp, done };

// How long after its ramp a stop waits for the joints to arrive (s), at
// most, and never up to the stop deadline.
inline constexpr double kStopSettleTime = 2.0;

// One bus's results for this cycle.
struct BusIo {
  // Its read came back in time: positions and health are this cycle's, and
  // the bus takes a write. A late bus (fresh = false) keeps its last
  // measurement and its joints hold the last command it was sent.
  bool fresh = false;
  std::span<const double> positions;     // per device
  std::span<const DeviceHealth> health;  // per device, of the latest transaction
  // Per device: temperature, current, voltage, error bits as last read
  // (empty: the bus reads none). A record whose `reads` has not changed
  // since the last cycle is not judged again.
  std::span<const HealthReading> readings{};
};

// One IMU's latest reading, as its reader thread last published it. The
// cycle judges its age by reading.time_s: older than the part's stale
// timeout, the sensor is silent.
struct ImuIo {
  bool valid = false;  // a frame has arrived (false until the first)
  ImuReading reading;
};

struct CycleInputs {
  double t = 0.0;  // seconds since the run began, at this cycle's deadline
  std::span<const BusIo> buses;
  std::span<const ImuIo> imus;           // per RobotModel::imus
  double motion_duration_s = 0.0;        // seconds of motion, then ramp home; 0 = until a stop
  bool stop = false;                     // ramp home and end
  bool abort = false;                    // torque off at once
  const MotionCommand* steer = nullptr;  // a new steering command, if one arrived
  const JogCommand* jog = nullptr;       // a new jog, if one arrived
  // A show's transport (play, pause, seek), if a command arrived; acts in
  // the motion phase only (handed to MotionSource::control() at the
  // motion's time).
  const ShowCommand* show = nullptr;
  // Manual mode (RunControls::manual) and the manual targets that arrived
  // since the last cycle, oldest first. Both act in the motion phase only.
  bool manual = false;
  std::span<const ManualTarget> manual_targets;
};

enum class EventKind : std::uint8_t {
  motion_started,
  motion_ended,
  device_fault,     // watchdog or hardware error: bus, device, health
  motion_fault,     // non-finite target: joint, value
  following_error,  // joint, value = error (rad or m)
  stop_deadline,    // the stop ramp ran over safety.stop_deadline_s: torque off now
  aborted,          // torque off now on request
  health_fault,     // bus, device, check, value: a health limit; the device is switched off
  health_warning,   // bus, device, check, value: logged and counted; the run goes on
  sensor_stale,     // an IMU silent past its stale timeout: bus = IMU index, value = age (s)
  tilted,           // the tilt watch: value = the larger of |roll| and |pitch| (rad)
  stop_unreached,   // joint, value = measured - stop pose: not there when torque went off
};

// Which health limit an event is about.
enum class HealthCheck : std::uint8_t { none, temperature, voltage, stall, error_bits };
const char* to_string(HealthCheck check);

struct CycleEvent {
  EventKind kind = EventKind::motion_started;
  double t = 0.0;
  int joint = -1;
  std::size_t bus = 0;
  std::size_t device = 0;
  DeviceHealth health = DeviceHealth::ok;
  double value = 0.0;
  HealthCheck check = HealthCheck::none;
};

struct CycleOutputs {
  std::vector<double> commands;                   // per joint: the filter's output
  std::vector<std::vector<double>> bus_commands;  // per bus, per device: goals to write
  std::vector<std::uint8_t> write;                // per bus: write bus_commands this cycle
  std::vector<CycleEvent> events;                 // this cycle's
  bool torque_off_now = false;                    // end without a ramp (deadline, abort)
  // CycleInputs::show acted this cycle (MotionSource::control at motion time
  // t - motion_start()), so a show's sound track can follow it.
  bool show_controlled = false;
};

// What ended the run, as far as the cycle knows.
struct CycleEnd {
  bool fault = false;       // a device, motion or following-error fault
  bool stopped = false;     // a stop request
  bool torque_cut = false;  // stop deadline or abort: torque went off without a ramp
  bool tilted = false;      // the tilt watch stopped the motion
};

class CycleState {
 public:
  explicit CycleState(const RobotModel& model);

  // Before activation: the measured pose and the motion's first pose. Returns
  // the start ramp's duration (the runner refuses one that is too long).
  double begin(const RobotModel& model, std::span<const double> measured,
               std::span<const double> first_pose);

  Phase phase() const { return phase_; }
  bool done() const { return phase_ == Phase::done; }
  // In the stop, before its ramp: the motion still plays, winding down.
  bool winding_down() const { return phase_ == Phase::stop_ramp && wind_end_ >= 0.0; }
  double motion_time() const { return motion_time_; }
  double motion_start() const { return motion_start_; }  // run time the motion began
  const CycleEnd& end() const { return end_; }
  std::span<const double> measured() const { return measured_; }
  // The watchdog's record, per bus and device (1 = faulted).
  const std::vector<std::vector<std::uint8_t>>& faulted() const { return faulted_; }
  bool joint_faulted(std::size_t j) const;
  // Every event of the run (bounded: the first ones are kept).
  std::span<const CycleEvent> log() const { return log_; }
  std::span<const std::uint64_t> late_cycles() const { return late_cycles_; }
  // Tracking error of the last command a joint's bus was sent against what
  // was measured after it: rms and max per joint.
  double rms_error(std::size_t j) const;
  double max_error(std::size_t j) const { return max_error_[j]; }
  std::uint64_t cycles() const { return cycles_; }
  // The safety filter's output velocity per joint (rad/s or m/s).
  std::span<const double> command_velocity() const { return filter_.velocity(); }
  // Manual mode: on (in the motion phase) and the held pose it steers to.
  bool manual() const { return manual_; }
  std::span<const double> manual_pose() const { return manual_pose_; }
  // The show's playhead as of this cycle (show false: the motion plays none).
  const ShowPosition& show() const { return show_; }
  // Per bus, per device: health readings over the run, and whether a health
  // fault asks for the device to be switched off (1).
  const std::vector<std::vector<HealthStats>>& health_stats() const { return health_stats_; }
  const std::vector<std::vector<std::uint8_t>>& switch_off() const { return switch_off_; }
  // Per IMU: cycles its reading was older than one report and one loop
  // period (late),
  // and whether it went stale past its timeout (faulted).
  std::span<const std::uint64_t> imu_late_cycles() const { return imu_late_; }
  // Per IMU: new readings taken, and reports due that never came (gaps
  // between readings, and the silence since the last one), one per report
  // period of the part.
  std::uint64_t imu_readings(std::size_t i) const { return imu_track_[i].readings; }
  std::uint64_t imu_missing(std::size_t i, double rate_hz) const;
  std::span<const std::uint8_t> imu_faulted() const { return imu_faulted_; }
  // The trunk's largest |roll| or |pitch| seen (rad; 0 without an IMU).
  double max_tilt() const { return max_tilt_; }

 private:
  friend const CycleOutputs& step(const RobotModel&, MotionSource&, CycleState&,
                                  const CycleInputs&);
  friend struct CycleStages;  // step()'s stages (cycle.cpp)
  void emit(const CycleEvent& event);
  void begin_stop(const RobotModel& model, double t);
  // A stop request in the motion: the source winds down first if it asks
  // to (MotionSource::wind_down), then the ramp home begins.
  void request_stop(const RobotModel& model, MotionSource& motion, double t);
  void begin_hold(const RobotModel& model, double t);

  Phase phase_ = Phase::start_ramp;
  double phase_start_ = 0.0;
  double motion_start_ = 0.0;
  double stop_start_ = 0.0;
  double arrived_since_ = -1.0;  // the joints measured at the stop pose since (s)
  double wind_end_ = -1.0;       // the motion winds down until (s); -1: not winding down
  double motion_time_ = 0.0;
  CycleEnd end_;
  std::uint64_t cycles_ = 0;

  SafetyFilter filter_;
  PoseRamp ramp_;
  std::vector<JointSlot> slots_;
  std::vector<double> measured_, targets_, ramp_from_, ramp_to_, jog_;
  bool manual_ = false;
  std::vector<double> manual_pose_;
  ShowPosition show_;
  std::vector<std::uint8_t> active_;            // per joint: its bus takes a write
  std::vector<std::vector<double>> last_sent_;  // per bus, per device
  std::vector<std::vector<std::uint8_t>> faulted_;
  std::vector<std::vector<double>> last_ok_;  // per bus, per device: time of last good answer
  std::vector<std::uint64_t> late_cycles_;
  // Following error per joint over the last window of answered cycles: a
  // ring of squared errors (joint-major, window_ entries each) and its sum.
  std::size_t window_ = 1;
  std::vector<double> err_ring_;
  std::vector<std::size_t> err_next_, err_count_;
  std::vector<double> err_sum_;
  std::vector<double> sq_error_, max_error_;
  std::vector<std::uint64_t> error_samples_;
  std::vector<CycleEvent> log_;
  // Health watch, per bus and device.
  struct HealthTrack {
    std::uint64_t reads = 0;  // the reading's `reads` last judged
    double stall_since = -1.0;
    std::uint8_t warned = 0;  // bit per HealthCheck: a warning episode is on
  };
  std::vector<std::vector<HealthTrack>> health_track_;
  std::vector<std::vector<HealthStats>> health_stats_;
  std::vector<std::vector<std::uint8_t>> switch_off_;
  // Sensors: per IMU, late cycles and the fault record; the trunk's reading
  // handed to the motion, and the tilt watch.
  std::vector<std::uint64_t> imu_late_;
  struct ImuTrack {
    double last = -1.0;  // the newest reading's time (s), -1 before the first
    std::uint64_t readings = 0;
    std::uint64_t missing = 0;  // in gaps between readings
  };
  std::vector<ImuTrack> imu_track_;
  double imu_now_ = 0.0;  // the latest cycle's time
  std::vector<std::uint8_t> imu_faulted_;
  double imu_start_ = 0.0;
  ImuReading trunk_;
  Sensors sensors_;
  double tilt_since_ = -1.0;
  double max_tilt_ = 0.0;
  CycleOutputs out_;
};

// One cycle: read the controls, take the measurements, watch the devices and
// the following error, change phase, sample, filter, and say what to write.
const CycleOutputs& step(const RobotModel& model, MotionSource& motion, CycleState& state,
                         const CycleInputs& in);

// The next deadline after a cycle that ended at `now`: one period on, or,
// when the cycle overran by whole periods, the first deadline still ahead
// (missed cycles are skipped, not caught up in a burst).
struct NextDeadline {
  Nanos deadline = 0;
  bool overrun = false;       // the cycle ended after its successor's deadline
  std::uint64_t skipped = 0;  // whole cycles left out
};
NextDeadline next_deadline(Nanos deadline, Nanos now, Nanos period);

}  // namespace animrt
