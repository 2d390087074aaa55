#include "animrt/runtime/figure.hpp"

#include <filesystem>
#include <stdexcept>

#include "animrt/controllers/show/show_audio.hpp"
#include "animrt/core/error.hpp"
#include "bus_failures.hpp"

namespace animrt {

namespace {

// The show files a motion plays (a show, or show layers).
void collect_shows(const MotionConfig& motion, std::vector<std::string>& out) {
  if (motion.type == "show") out.push_back(motion.file);
  for (const auto& layer : motion.layers) collect_shows(layer, out);
}

}  // namespace

Figure::Figure(LoadedRobot robot, FigureBackend& backend, const FigureOptions& options)
    : steering_(std::move(robot.steering)),
      balanced_(robot.balanced),
      backend_(backend),
      lockstep_(options.lockstep) {
  // Every refusal comes before the first device starts.
  if (lockstep_ && !backend_.keeps_run_clock()) {
    throw std::invalid_argument(
        "a lockstep run needs a backend whose devices keep the run's clock; " + backend_.name() +
        " devices keep the wall's");
  }
  if (!robot.motion) throw std::invalid_argument("figure " + robot.config.name + ": no motion");
  for (const std::string& line : robot.warnings) {
    if (options.warn) options.warn(line);
  }
  backend_.check(robot.config, lockstep_);
  backend_.adjust(robot.config, lockstep_);
  if (options.edit) options.edit(robot.config);
  for (const std::string& line : backend_.start(robot.config, clock())) {
    if (options.log) options.log(line);
  }
  show_ = robot.motion->show_position(0.0);
  config_ = robot.config;
  std::vector<std::unique_ptr<ActuatorBus>> buses;
  // Every port is tried, so one error names all that cannot be opened.
  std::vector<std::string> failed;
  for (std::size_t b = 0; b < config_.buses.size(); ++b) {
    std::unique_ptr<ActuatorBus> bus;
    try {
      bus = make_bus(config_.buses[b]);
    } catch (const DeviceError& e) {
      failed.emplace_back(e.what());
      continue;
    }
    if (options.wrap_bus) bus = options.wrap_bus(std::move(bus), b);
    buses_.push_back(bus.get());
    buses.push_back(std::move(bus));
  }
  // Each IMU read on its own thread from its port, stamped on the run's clock.
  for (const ImuConfig& imu : config_.imus) {
    imus_.push_back(
        std::make_unique<imu::RvcReader>(open_serial(imu.port, imu.baud), imu, clock(), Nanos{0}));
  }
  if (!failed.empty()) {
    // The buses that did open are configured too, so that a link that
    // connects only then (Modbus TCP) or devices that do not answer are
    // named in the same error; nothing is switched on.
    for (ActuatorBus* bus : buses_) {
      try {
        bus->configure();
      } catch (const DeviceError& e) {
        failed.emplace_back(e.what());
      }
      bus->deactivate();
    }
    throw DeviceError(bus_failures(failed, config_.buses.size()));
  }
  if (options.audio_sink) {
    std::vector<std::string> shows;
    collect_shows(config_.motion, shows);
    const auto warn = [&options](const std::string& line) {
      if (options.warn) options.warn(line);
    };
    audio_ = open_show_audio(shows, lockstep_, options.audio_sink, wall_clock_, warn);
    // A show with its sound playing runs on the sound output's clock.
    for (auto& player : audio_)
      robot.motion->follow_sound(player->show_file(), player->sound_clock());
  }
  runner_ =
      std::make_unique<Runner>(std::move(robot.config), std::move(buses), std::move(robot.motion));
}

Figure::~Figure() {
  dashboard_.reset();
  audio_.clear();
  runner_.reset();  // the buses close before their devices stop
  imus_.clear();
  backend_.stop();
}

const Clock& Figure::clock() const {
  return lockstep_ ? static_cast<const Clock&>(lockstep_clock_)
                   : static_cast<const Clock&>(wall_clock_);
}

RunOptions Figure::run_options() {
  RunOptions options;
  options.lockstep_clock = lockstep_ ? &lockstep_clock_ : nullptr;
  options.backend_name = backend_.name();
  options.raise_device_threads = [this](int priority) { return backend_.raise_threads(priority); };
  for (auto& imu : imus_) options.imu_readings.push_back(&imu->readings());
  return options;
}

DashboardServer& Figure::serve_dashboard(DashboardSetup setup, RunControls& controls) {
  setup.robot = config_.name;
  setup.backend = backend_.name();
  setup.bus_protocols.clear();
  for (const BusConfig& bus : config_.buses) setup.bus_protocols.push_back(bus.protocol);
  setup.motion_kind = config_.motion.type;
  setup.motion_name = std::filesystem::path(config_.motion.file).stem().string();
  setup.show = show_.show;
  setup.show_duration_s = show_.duration_s;
  dashboard_.reset();
  monitor_ = std::make_unique<RunMonitor>(runner_->model());
  dashboard_ = std::make_unique<DashboardServer>(*monitor_, controls, std::move(setup));
  return *dashboard_;
}

RunSummary Figure::run(const RunOptions& options) {
  // Its curves alone are not the walk that was scored: refused before anything moves.
  if (balanced_ && !balanced_->has_legs()) {
    throw InputError(balanced_->gains().where, "balance",
                     "the gait's reflex has no legs: build them from the robot's model "
                     "(BalancedGaitSource::attach) before the run");
  }
  RunOptions run = options;
  run.on_motion_start = [this, start = options.on_motion_start](Nanos t0) {
    for (auto& player : audio_) player->start(t0);
    if (start) start(t0);
    backend_.motion_started(t0);
  };
  run.on_motion_end = [this, end = options.on_motion_end] {
    for (auto& player : audio_) player->stop();
    if (end) end();
    backend_.motion_ended();
  };
  // The sound track follows the show's pause, seek and play.
  if (!audio_.empty()) {
    run.on_show_command = [this, command = options.on_show_command](const ShowCommand& c,
                                                                    double t) {
      for (auto& player : audio_) player->control(c, t);
      if (command) command(c, t);
    };
  }
  if (dashboard_ && run.monitor == nullptr) run.monitor = monitor_.get();
  struct StopServing {
    DashboardServer* server;
    ~StopServing() {
      if (server) server->stop();
    }
  } stop_serving{dashboard_.get()};
  RunSummary summary = runner_->run(run);
  backend_.report(summary);
  return summary;
}

}  // namespace animrt
