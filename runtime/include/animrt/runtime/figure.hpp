#pragma once
// One way to assemble a figure: a loaded robot, the backend that stands
// behind its buses and a few options make a session ready to run (the
// devices behind the buses started, the buses built, the runner holding them
// and the motion). `animrt run`, the benchmarks and the test rigs all build
// their figures here, so what a test or a benchmark runs is what the CLI runs.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/imu/rvc_reader.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/figure_backend.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/run_monitor.hpp"
#include "animrt/runtime/runner.hpp"

namespace animrt {

class AudioSink;        // controllers/show/show_audio.hpp, kept out of this header:
class ShowAudioPlayer;  // it brings Eigen, which httplib's <resolv.h> breaks

struct FigureOptions {
  // The run's clock is simulated (advanced one period per cycle): needs a
  // backend whose devices keep the run's clock.
  bool lockstep = false;
  // Edits the robot after the backend adjusted it, before its devices start.
  std::function<void(RobotConfig&)> edit;
  // Wraps each bus as it is built (bus index): a test watches its calls.
  std::function<std::unique_ptr<ActuatorBus>(std::unique_ptr<ActuatorBus>, std::size_t)> wrap_bus;
  // Lines from the backend as it starts (which devices, where).
  std::function<void(const std::string&)> log;
  // Plays the sound tracks of the shows the motion plays, started with the
  // motion, through sinks made here (none: silent). A lockstep run plays
  // nothing. What cannot be played is told to `warn`, and the run goes on.
  std::function<std::unique_ptr<AudioSink>(int rate)> audio_sink;
  std::function<void(const std::string&)> warn;
};

class Figure {
 public:
  // Throws InputError for a robot the backend cannot stand behind and
  // std::invalid_argument for a lockstep run on a backend that keeps the
  // wall's clock, both before any device starts; DeviceError or InputError
  // from a device that does not start. `backend` outlives the figure.
  Figure(LoadedRobot robot, FigureBackend& backend, const FigureOptions& options = {});
  ~Figure();  // the buses close, then the backend stops
  Figure(const Figure&) = delete;
  Figure& operator=(const Figure&) = delete;

  // The robot as its buses were opened (ports at the backend's devices).
  const RobotConfig& config() const { return config_; }
  // A steerable gait's command range, if the motion is one.
  const std::optional<GaitSteering>& steering() const { return steering_; }
  const Clock& clock() const;
  bool lockstep() const { return lockstep_; }
  FigureBackend& backend() { return backend_; }
  // A bus as built (behind its wrapper, if any); the runner drives it in run().
  ActuatorBus& bus(std::size_t index) { return *buses_.at(index); }
  std::size_t bus_count() const { return buses_.size(); }
  const Runner& runner() const { return *runner_; }

  // The options every run of this figure starts from: its lockstep clock,
  // the backend's name and device threads.
  RunOptions run_options();
  // Serves the dashboard for the next run. `setup` gives where and how; the
  // figure fills in what it knows (robot, backend, buses, motion).
  DashboardServer& serve_dashboard(DashboardSetup setup, RunControls& controls);
  // Runs the whole lifecycle (Runner::run) with the sound tracks, the
  // backend's motion hooks and the dashboard added to `options`, the
  // backend's measures added to the summary. A dashboard stops serving when
  // the run returns.
  RunSummary run(const RunOptions& options);

 private:
  RobotConfig config_;
  std::optional<GaitSteering> steering_;
  const BalancedGaitSource* balanced_ = nullptr;  // a gait with balance:, or null
  ShowPosition show_;
  FigureBackend& backend_;
  bool lockstep_;
  ManualClock lockstep_clock_;
  MonotonicClock wall_clock_;
  std::vector<ActuatorBus*> buses_;
  std::vector<std::unique_ptr<imu::RvcReader>> imus_;
  std::unique_ptr<Runner> runner_;
  std::vector<std::unique_ptr<ShowAudioPlayer>> audio_;
  std::unique_ptr<RunMonitor> monitor_;
  std::unique_ptr<DashboardServer> dashboard_;
};

}  // namespace animrt
