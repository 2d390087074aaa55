#include "support/sim_rig.hpp"

#include <fstream>
#include <stdexcept>

namespace animrt::test {

SimRig::SimRig(const std::string& robot_file, const RigSettings& settings)
    : backend_(SimulatedBackend::Settings{"", settings.physics}), sims(backend_.devices()) {
  LoadedRobot loaded = load_robot(robot_file);
  if (settings.edit_motion) settings.edit_motion(loaded);
  auto owner = std::make_unique<ProbeSource>(std::move(loaded.motion));
  probe = owner.get();
  loaded.motion = std::move(owner);
  hook_ = [this](std::size_t bus, BusCall call, std::uint64_t index) {
    bus_call(bus, call, index);
  };
  FigureOptions options;
  options.lockstep = settings.lockstep;  // timeouts widen as in `animrt run --lockstep`
  options.edit = [&settings](RobotConfig& config) {
    for (auto& bus : config.buses) {
      bus.timeout_s = std::max(bus.timeout_s, settings.min_bus_timeout_s);
      bus.sim.wire_time = settings.wire_time;
    }
    if (settings.edit) settings.edit(config);
  };
  options.wrap_bus = [this](std::unique_ptr<ActuatorBus> bus, std::size_t b) {
    auto watched = std::make_unique<WatchedBus>(std::move(bus), b, hook_);
    watched_.push_back(watched.get());
    return std::unique_ptr<ActuatorBus>(std::move(watched));
  };
  robot.steering = loaded.steering;
  figure_ = std::make_unique<Figure>(std::move(loaded), backend_, options);
  robot.config = figure_->config();
}

SimRig::~SimRig() {
  figure_.reset();  // buses close before their devices stop
}

const Clock& SimRig::clock() const { return figure_->clock(); }

SimulatedBus& SimRig::sim(const std::string& bus_name) {
  for (std::size_t b = 0; b < robot.config.buses.size(); ++b) {
    if (robot.config.buses[b].name == bus_name) return *sims[b];
  }
  throw std::out_of_range("no bus " + bus_name);
}

RunOptions SimRig::options(double duration, const std::string& telemetry) {
  RunOptions options = figure_->run_options();
  options.duration_s = duration;
  options.request_realtime = false;
  options.telemetry_path = telemetry;
  // The devices' threads keep their priority, whatever a test asks of the loop.
  options.raise_device_threads = nullptr;
  return options;
}

RunSummary SimRig::run(double duration, const std::string& telemetry) {
  return run(options(duration, telemetry));
}

RunSummary SimRig::run(const RunOptions& options) { return figure_->run(options); }

void SimRig::bus_call(std::size_t bus, BusCall call, std::uint64_t index) {
  if (watch_ != nullptr) {
    switch (call) {
      case BusCall::activate:
        ++active_buses_;
        break;
      case BusCall::read:
        if (!in_window_.load() &&
            active_buses_.load() == static_cast<int>(robot.config.buses.size())) {
          in_window_.store(true);
          watch_->open();
        }
        if (bus == 0 && in_window_.load()) ++phase_cycles_[phase_.load()];
        break;
      case BusCall::deactivate:
        if (in_window_.exchange(false)) watch_->close();
        break;
      case BusCall::configure:
      case BusCall::write:
        break;
    }
  }
  if (on_bus_call) on_bus_call(bus, call, index);
}

RunSummary SimRig::run_watching(RunAllocationWatch& watch, const RunOptions& options) {
  RunOptions watched = options;
  watched.on_motion_start = [this, &watch, start = options.on_motion_start](Nanos t) {
    phase_.store(static_cast<int>(RunPhase::motion));
    watch.set_phase(RunPhase::motion);
    if (start) start(t);
  };
  watched.on_motion_end = [this, &watch, end = options.on_motion_end] {
    phase_.store(static_cast<int>(RunPhase::stop_ramp));
    watch.set_phase(RunPhase::stop_ramp);
    if (end) end();
  };
  watch_ = &watch;
  active_buses_ = 0;
  phase_ = static_cast<int>(RunPhase::start_ramp);
  for (auto& c : phase_cycles_) c.store(0);
  watch.set_phase(RunPhase::start_ramp);
  struct Reset {
    SimRig& rig;
    ~Reset() {
      rig.watch_->close();
      rig.watch_ = nullptr;
      rig.in_window_ = false;
    }
  } reset{*this};
  return figure_->run(watched);
}

std::string lockstep_problems(const RunSummary& s) {
  std::string out;
  for (const auto& fault : s.faults) out += "fault: " + fault + "\n";
  for (const auto& bus : s.buses) {
    if (bus.late_cycles != 0) {
      out += "bus " + bus.name + ": " + std::to_string(bus.late_cycles) + " late cycles\n";
    }
  }
  for (const auto& d : s.devices) {
    const DeviceStatus& st = d.status;
    if (st.timeouts + st.crc_errors + st.protocol_errors + st.hardware_errors + st.exceptions !=
        0) {
      out += d.joint + ": " + std::to_string(st.timeouts) + " timeouts, " +
             std::to_string(st.crc_errors) + " CRC errors, " + std::to_string(st.protocol_errors) +
             " protocol errors, " + std::to_string(st.hardware_errors) + " hardware errors, " +
             std::to_string(st.exceptions) + " exceptions\n";
    }
  }
  return out;
}

std::string first_difference(const std::string& file_a, const std::string& file_b) {
  std::ifstream a(file_a), b(file_b);
  if (!a || !b) return "cannot open " + (!a ? file_a : file_b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool more_a = static_cast<bool>(std::getline(a, la));
    const bool more_b = static_cast<bool>(std::getline(b, lb));
    if (!more_a && !more_b) return "";
    if (!more_a) la = "(end of file)";
    if (!more_b) lb = "(end of file)";
    if (la != lb) {
      return "line " + std::to_string(line) + ":\n  " + file_a + ": " + la + "\n  " + file_b +
             ": " + lb;
    }
  }
}

}  // namespace animrt::test
