// animrt: validate a robot, run it on hardware or on simulated devices, or
// serve simulated devices for another program.

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <thread>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "evolve_command.hpp"
#include "head_command.hpp"

namespace {

// Exit codes (documented in the README).
constexpr int kExitOk = 0;
constexpr int kExitUsage = 1;
constexpr int kExitInvalidInput = 2;
constexpr int kExitDeviceError = 3;

std::atomic<bool> g_stop{false};

void on_signal(int) { g_stop.store(true); }

void install_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int cmd_validate(const std::string& path) {
  animrt::LoadedRobot robot = animrt::load_robot(path);
  std::size_t devices = 0;
  for (const auto& bus : robot.config.buses) devices += bus.actuators.size();
  std::cout << path << ": ok (" << robot.config.joints.size() << " joints, "
            << robot.config.buses.size() << " bus" << (robot.config.buses.size() == 1 ? "" : "es")
            << ", " << devices << " devices, " << robot.config.motion.type << " "
            << robot.config.motion.file << ")\n";
  return kExitOk;
}

struct RunArgs {
  std::string config;
  std::string backend = "sim";
  double duration = 0.0;
  std::string telemetry;
  std::string summary_json;
  bool lockstep = false;
  bool no_realtime = false;
};

int cmd_run(const RunArgs& args) {
  animrt::LoadedRobot robot = animrt::load_robot(args.config);
  if (args.lockstep && args.backend != "sim") {
    spdlog::error("--lockstep needs --backend sim (hardware runs in real time)");
    return kExitUsage;
  }
  animrt::ManualClock lockstep_clock;
  animrt::MonotonicClock wall_clock;
  std::vector<std::unique_ptr<animrt::SimulatedBus>> simulated;
  if (args.backend == "sim") {
    const animrt::Clock& clock = args.lockstep ? static_cast<const animrt::Clock&>(lockstep_clock)
                                               : static_cast<const animrt::Clock&>(wall_clock);
    simulated = animrt::start_simulated_devices(robot.config.buses, clock);
    for (const auto& sim : simulated) spdlog::info("simulated devices: {}", sim->describe());
  }
  std::vector<std::unique_ptr<animrt::ActuatorBus>> buses;
  for (const auto& bus : robot.config.buses) buses.push_back(animrt::make_bus(bus));

  animrt::RunOptions options;
  options.duration_s = args.duration;
  options.lockstep_clock = args.lockstep ? &lockstep_clock : nullptr;
  options.request_realtime = !args.no_realtime;
  options.telemetry_path = args.telemetry;
  options.stop_request = &g_stop;
  options.backend_name = args.backend;
  options.log = [](const std::string& message) { spdlog::info("{}", message); };

  animrt::Runner runner(std::move(robot.config), std::move(buses), std::move(robot.motion));
  animrt::RunSummary summary = runner.run(options);
  std::cout << animrt::format_summary(summary) << std::flush;
  if (!args.summary_json.empty()) {
    std::ofstream out(args.summary_json);
    if (!out) {
      spdlog::error("cannot write summary file {}", args.summary_json);
      return kExitUsage;
    }
    out << animrt::to_json(summary).dump(2) << '\n';
  }
  return summary.exit_code();
}

int cmd_sim(const std::string& path) {
  animrt::LoadedRobot robot = animrt::load_robot(path);
  animrt::MonotonicClock clock;
  // Served for other programs: CAN devices go on the real interfaces.
  animrt::sim::set_can_sim_attach(animrt::sim::CanSimAttach::socketcan);
  auto simulated = animrt::start_simulated_devices(robot.config.buses, clock);
  for (const auto& sim : simulated) std::cout << sim->describe() << '\n';
  std::cout << std::flush;
  while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  auto logger = spdlog::stderr_color_mt("animrt");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("%^[%l]%$ %v");

  CLI::App app{"animrt: real-time motion for animatronic figures"};
  app.require_subcommand(1);

  std::string validate_path;
  auto* validate = app.add_subcommand("validate", "Check a robot file and the files it names");
  validate->add_option("FILE", validate_path, "robot file (YAML)")->required();

  RunArgs run_args;
  auto* run = app.add_subcommand("run", "Run a robot's motion on hardware or simulated devices");
  run->add_option("CONFIG", run_args.config, "robot file (YAML)")->required();
  run->add_option("--backend", run_args.backend, "sim (simulated devices on ptys) or hardware")
      ->check(CLI::IsMember({"sim", "hardware"}))
      ->capture_default_str();
  run->add_option("--duration", run_args.duration, "seconds of motion, then ramp home (0 = until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--telemetry", run_args.telemetry, "write per-cycle CSV telemetry to this file");
  run->add_option("--summary-json", run_args.summary_json, "write the run summary as JSON");
  run->add_flag("--lockstep", run_args.lockstep,
                "simulated clock: run as fast as the devices answer (sim backend only)");
  run->add_flag("--no-realtime", run_args.no_realtime, "do not request SCHED_FIFO or mlockall");

  std::string sim_path;
  auto* sim = app.add_subcommand("sim", "Serve a robot's simulated devices until Ctrl-C");
  sim->add_option("CONFIG", sim_path, "robot file (YAML)")->required();

  animrt::cli::add_evolve_command(app);
  animrt::cli::add_head_command(app);
  CLI11_PARSE(app, argc, argv);
  install_signal_handlers();
  try {
    if (*validate) return cmd_validate(validate_path);
    if (*run) return cmd_run(run_args);
    if (*sim) return cmd_sim(sim_path);
  } catch (const animrt::InputError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return kExitInvalidInput;
  } catch (const animrt::DeviceError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return kExitDeviceError;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return kExitUsage;
  }
  return kExitUsage;
}
