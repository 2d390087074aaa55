#pragma once
// The shell around step() for one run: the buses' I/O threads, the clock and
// its deadlines, the controls' mailboxes, telemetry and the monitor. Every
// buffer a cycle touches is allocated by the constructor; cycle() itself
// never allocates, locks a mutex, logs or touches a file.
//
// A cycle runs in stages: wake at the deadline, post the reads, wait for
// them within the read budget, take the reads that came back, gather the
// controls, step(), publish to the monitor, notify the callbacks, post the
// writes, record telemetry, pace to the next deadline.
//
// Device statuses: each bus alone writes its DeviceStatus. What the loop
// knows beyond it (requests a bus threw on, the cycle's faults) stays in the
// loop's records and the cycle state; device_view() combines the two for
// the readers (summary, monitor).

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/cycle.hpp"
#include "animrt/runtime/loop_stats.hpp"
#include "animrt/runtime/mcap_recorder.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/runtime/telemetry.hpp"
#include "bus_worker.hpp"

namespace animrt {

// Owns activation: whatever ends the run (return, exception), every bus that
// was switched on is switched off. A bus counts as on from the moment its
// activate() is called, so one that fails half-way is switched off too.
class ActivationGuard {
 public:
  explicit ActivationGuard(std::vector<std::unique_ptr<ActuatorBus>>& buses) : buses_(buses) {}
  ~ActivationGuard() { release(); }
  ActivationGuard(const ActivationGuard&) = delete;
  ActivationGuard& operator=(const ActivationGuard&) = delete;

  void activate_all();
  void release();

 private:
  std::vector<std::unique_ptr<ActuatorBus>>& buses_;
  std::size_t activated_ = 0;
};

class RunLoop {
 public:
  // Opens the telemetry file (throws naming it) and starts one I/O thread
  // per bus, at a real-time priority when summary.sched_fifo says the loop
  // has one; refusals are noted in the summary.
  RunLoop(const RobotModel& model, std::vector<std::unique_ptr<ActuatorBus>>& buses,
          MotionSource& motion, const RunOptions& options, CycleState& state,
          std::span<const std::vector<double>> bus_positions, RunSummary& summary);
  // The motion lets go of the run's clock (which may be this loop's own)
  // before anything of the loop goes, whatever ends the run.
  ~RunLoop() { motion_.stop(); }
  RunLoop(const RunLoop&) = delete;
  RunLoop& operator=(const RunLoop&) = delete;

  // Torque on (the guard switches it off again whatever ends the run).
  void activate() { activation_.activate_all(); }
  // Cycles until the cycle state is done or torque must go off at once.
  // Returns whether it ended by cutting torque without the stop ramp.
  bool run();
  // Stops the I/O threads and the monitor, switches every bus off and
  // drains the telemetry.
  void finish();

  // The run's view of bus b's devices: the bus's own statuses, the requests
  // it threw on (timeouts of every device it was asked about) and the
  // cycle's faults.
  std::span<const DeviceStatus> device_view(std::size_t b) const { return view_[b]; }
  const MicrosHistogram& period() const { return period_hist_; }
  const MicrosHistogram& jitter() const { return jitter_hist_; }
  const MicrosHistogram& busy() const { return busy_hist_; }
  const MicrosHistogram& bus_io(std::size_t b) const { return bus_hist_[b]; }
  const TelemetryWriter* telemetry() const { return writer_ ? &*writer_ : nullptr; }
  McapRecorder* recording() { return recorder_ ? &*recorder_ : nullptr; }
  std::uint64_t telemetry_dropped() const { return ring_.dropped(); }

 private:
  struct Wake {
    Nanos run;   // on the run's clock
    Nanos wall;  // on the wall clock, for the work per cycle
  };
  Wake wake();
  void post_reads();
  void wait_for(bool reads, Nanos deadline);
  void take_reads();
  void gather_inputs();
  void take_imu(std::size_t i);
  void publish(const CycleOutputs& out);
  void notify(const CycleOutputs& out);
  void post_writes(const CycleOutputs& out);
  void record(const CycleOutputs& out);
  void record_mcap(const CycleOutputs& out);
  void record_mcap_health();
  void add_record_channels();
  void pace(const Wake& woke);
  void mark_faults(std::size_t b);
  void update_view(std::size_t b);
  void count_io(std::size_t b);

  const RobotModel& model_;
  std::vector<std::unique_ptr<ActuatorBus>>& buses_;
  MotionSource& motion_;
  const RunOptions& options_;
  CycleState& state_;
  RunSummary& summary_;
  const MonotonicClock wall_;
  const Clock& clock_;
  const Nanos period_;

  // Telemetry's health columns: per (bus, device) whose bus reads health,
  // five values each after the joints' columns; then per IMU its attitude
  // (w, x, y, z) and angular rates.
  std::vector<JointSlot> health_columns_;
  std::vector<std::string> health_names_;
  TelemetryRing ring_;
  std::optional<TelemetryWriter> writer_;
  std::optional<McapRecorder> recorder_;
  std::size_t status_every_ = 1;  // cycles between two device status records
  // The recording's health and IMU channels (npos: not recorded).
  std::size_t health_channel_ = static_cast<std::size_t>(-1);
  std::size_t imu_channel_ = static_cast<std::size_t>(-1);
  std::vector<std::uint64_t> health_seen_;  // per health column: the reading last recorded
  bool stop_recorded_ = false;
  std::vector<double> record_;
  MicrosHistogram period_hist_, jitter_hist_, busy_hist_;
  std::vector<MicrosHistogram> bus_hist_;
  std::vector<BusIo> io_;
  std::vector<std::vector<DeviceHealth>> health_;
  std::vector<std::vector<HealthReading>> readings_;
  std::vector<std::vector<DeviceStatus>> view_;
  std::vector<std::uint8_t> pending_;  // a read posted, not yet used
  std::vector<std::uint64_t> io_seen_;
  // Controls taken from the mailboxes this cycle.
  std::vector<ImuIo> imu_io_;  // per IMU: the latest reading taken
  // Lockstep, per IMU: its last wait gave up (a silent part); it is not
  // waited for again until a frame arrives.
  std::vector<std::uint8_t> imu_silent_;
  CycleInputs in_;
  MotionCommand steer_;
  ShowCommand show_;
  JogCommand jog_;
  std::vector<ManualTarget> manual_;
  std::vector<std::span<const DeviceStatus>> monitor_devices_;

  Nanos start_ = 0;
  Nanos deadline_ = 0;
  Nanos previous_wake_ = -1;
  double last_period_s_ = -1.0;

  // Declared after everything above and before the I/O threads, so that on
  // any exit the threads stop first and the buses are switched off after
  // them.
  ActivationGuard activation_;
  std::atomic<std::uint32_t> io_done_{0};
  std::vector<std::unique_ptr<BusWorker>> workers_;
};

}  // namespace animrt
