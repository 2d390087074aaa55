#pragma once
// The lifecycle of a run: configure (open buses, ping every device, read the
// pose), plan (the start ramp; everything the cycle touches is allocated),
// activate (torque on), run (read -> sample -> filter -> write on absolute
// deadlines: the start ramp from the measured pose to the motion's first
// pose, the motion, and on the end of the duration, a stop request or a
// fault the stop ramp to home), deactivate (torque off). The runner is the
// shell around the cycle (cycle.hpp): it holds the lifecycle; threads, clock
// and the buses' I/O are the run loop's (src/run_loop.hpp); what happens in
// a cycle is step()'s.

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/imu.hpp"
#include "animrt/core/mailbox.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/runtime/run_controls.hpp"
#include "animrt/runtime/run_heartbeat.hpp"
#include "animrt/runtime/run_monitor.hpp"
#include "animrt/runtime/run_summary.hpp"

namespace animrt {

struct RunOptions {
  double duration_s = 0.0;  // seconds of motion; 0 = until a stop request
  // Lockstep: the loop never sleeps; it advances this clock by one period per
  // cycle (share it with simulated devices for deterministic runs).
  ManualClock* lockstep_clock = nullptr;
  bool request_realtime = true;  // SCHED_FIFO + mlockall (real-time runs only)
  int realtime_priority = 80;
  std::string telemetry_path;  // CSV, empty = none
  std::string record_path;     // MCAP (mcap_recorder.hpp), empty = none
  // Stop, abort, steering and jogs from other threads (a signal handler, a
  // dashboard, a herd); none when null.
  RunControls* controls = nullptr;
  std::string backend_name = "hardware";  // for the report
  // Lifecycle messages; never called from inside the cycle.
  std::function<void(const std::string&)> log;
  // Called from inside the cycle when the motion starts (with the time of its
  // t = 0 on the run's clock) and when it ends (stop, fault or duration), so
  // a show's sound track can follow it. Must not block, lock or allocate.
  std::function<void(Nanos)> on_motion_start;
  std::function<void()> on_motion_end;
  // Called from inside the cycle when the show took a transport command (a
  // dashboard's play, pause or seek), with the motion time it acted at (as
  // MotionSource::control got it), so a show's sound track can follow it.
  // Same rules as on_motion_start.
  std::function<void(const ShowCommand&, double)> on_show_command;
  // Readers of the run (a dashboard): the cycle publishes its state, timing
  // and events here, lock-free. Built on this runner's model().
  RunMonitor* monitor = nullptr;
  // The loop's pulse for a supervisor (a service manager's watchdog): beaten
  // after every cycle, ended after the last; none when null.
  RunHeartbeat* heartbeat = nullptr;
  // Threads outside the runner that its buses wait on (simulated devices'):
  // in a real-time run, called before configure with the priority just below
  // the bus I/O threads'; returns why, for each thread that could not have it
  // (the summary's notes).
  std::function<std::vector<std::string>(int priority)> raise_device_threads;
  // Per IMU of the robot file (in its order): where the IMU's reader posts
  // its readings, time_s in seconds on the run's clock (the loop makes it
  // time since the run began). A configured IMU without one
  // never reports and is faulted as stale.
  std::vector<Mailbox<ImuReading>*> imu_readings;
};

class Runner {
 public:
  Runner(RobotConfig config, std::vector<std::unique_ptr<ActuatorBus>> buses,
         std::unique_ptr<MotionSource> motion);
  ~Runner();

  // Runs the whole lifecycle. Throws DeviceError when bring-up fails or the
  // start ramp would take longer than safety.start_ramp_max_s; a fault during
  // the run ends it through the stop ramp and is reported in the summary.
  // Whatever ends the run (return, exception), every bus that was activated
  // is deactivated.
  RunSummary run(const RunOptions& options);

  // The immutable model of the run (joints, limits, buses), known before it.
  const RobotModel& model() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace animrt
