#pragma once
// What the cycle publishes for readers of the run (the dashboard): the
// latest state in a preallocated sequence-locked block, and every cycle's
// timing and every event in single-producer single-consumer rings. The
// cycle's side never blocks, locks or allocates; a reader copies the block
// and retries when the cycle wrote during the copy.
//
// One writer (the runner's loop thread) and one reader thread.

#include <atomic>
#include <bit>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/runtime/cycle.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/runtime/telemetry.hpp"

namespace animrt {

enum class RunPhaseView : std::uint8_t { configure, start_ramp, motion, stop_ramp, ended };
const char* to_string(RunPhaseView phase);

// One IMU as the cycle last saw it (per RobotModel::imus).
struct ImuView {
  bool valid = false;  // a reading has arrived
  ImuReading reading;  // attitude, angular rates and the time the part measured them
  std::uint64_t late_cycles = 0;
  std::uint64_t missing_reports = 0;
  bool faulted = false;  // silent past its stale timeout
};

// The reader's copy of the latest published state.
struct RunView {
  bool published = false;  // the run has published at least once
  double t_s = 0.0;        // run time at the last cycle's deadline
  RunPhaseView phase = RunPhaseView::configure;
  double motion_time_s = 0.0;
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;
  std::uint64_t skipped = 0;
  bool manual = false;
  bool steered = false;                             // a steering command has reached the motion
  MotionCommand steer;                              // the last one
  ShowPosition show;                                // a show's playhead (show false: none)
  std::vector<double> cmd, meas, vel, manual_pose;  // per joint
  std::vector<std::uint64_t> late;                  // per bus
  std::vector<DeviceStatus> devices;                // per device, bus after bus
  std::vector<ImuView> imus;                        // per IMU
};

// One cycle's timing, as the reader drains it.
struct CycleTiming {
  double t_s = 0.0;        // the cycle's deadline, run time
  double period_s = -1.0;  // since the previous cycle's start (-1: first cycle)
  double jitter_s = 0.0;   // start - deadline
  double busy_s = 0.0;     // wake to end of writes
};

class RunMonitor {
 public:
  explicit RunMonitor(const RobotModel& model);

  const RobotModel& model() const { return model_; }
  std::size_t device_count() const { return devices_; }

  // --- writer side (the cycle): never blocks, locks or allocates ----------
  // Publishes the cycle's state. `devices` is per bus: the statuses of a bus
  // whose I/O thread is idle (fresh this cycle), or an empty span to keep
  // that bus's last published statuses. `imus` is the cycle's IMU inputs
  // (empty: the IMUs' words stay as they are).
  void publish(double t, const CycleState& state, std::span<const double> commands,
               std::span<const std::span<const DeviceStatus>> devices, std::uint64_t overruns,
               std::uint64_t skipped, const MotionCommand* steer, std::span<const ImuIo> imus = {});
  // The run is over (after the last cycle).
  void publish_ended();
  // A recorded sample (a replay): time, phase and per joint command,
  // measurement and velocity; the rest of the block stays as it is.
  void publish_sample(double t, RunPhaseView phase, std::uint64_t cycle,
                      std::span<const double> cmd, std::span<const double> meas,
                      std::span<const double> vel);
  void push_timing(const CycleTiming& timing);
  void push_event(const CycleEvent& event);

  // --- reader side ---------------------------------------------------------
  // Copies the latest state into `view` (sized on first use).
  void read(RunView& view) const;
  bool pop_timing(CycleTiming& timing);
  bool pop_event(CycleEvent& event);
  std::uint64_t timing_dropped() const { return timing_.dropped(); }

 private:
  void store(std::size_t word, double value) {
    words_[word].store(std::bit_cast<std::uint64_t>(value), std::memory_order_relaxed);
  }
  void store_u(std::size_t word, std::uint64_t value) {
    words_[word].store(value, std::memory_order_relaxed);
  }
  void begin_write();
  void end_write();
  void publish_imus(const CycleState& state, std::span<const ImuIo> imus);

  RobotModel model_;
  std::size_t joints_ = 0, buses_ = 0, devices_ = 0, imus_ = 0;
  std::size_t imu_words_ = 0;               // the first IMU word
  std::vector<std::size_t> device_offset_;  // per bus: first device word block
  std::size_t word_count_ = 0;
  std::unique_ptr<std::atomic<std::uint64_t>[]> words_;
  std::atomic<std::uint64_t> sequence_{0};
  bool steered_ = false;
  MotionCommand steer_;
  TelemetryRing timing_;
  TelemetryRing events_;
  mutable std::vector<std::uint64_t> scratch_;  // reader's
};

}  // namespace animrt
