// animrt: validate a robot, run it on hardware or on simulated devices, or
// serve simulated devices for another program.

#include <fcntl.h>
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>

#include "animrt/controllers/show/show_audio.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/emergency_stop.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/sim/mujoco/mujoco_figure.hpp"
#include "animrt/sim/mujoco/mujoco_leg_model.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "calibrate_command.hpp"
#include "dashboard_address.hpp"
#include "data_dir.hpp"
#include "doctor_command.hpp"
#include "fault_injection.hpp"
#include "option_checks.hpp"
#include "output_file.hpp"
#include "record_command.hpp"
#include "run_herd.hpp"
#include "scan_command.hpp"
#include "serve_command.hpp"
#include "servo_command.hpp"
#include "sim_command.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"
#include "tools_exec.hpp"
#include "view_command.hpp"

namespace {

using animrt::cli::kExitDeviceError;
using animrt::cli::kExitInvalidInput;
using animrt::cli::kExitOk;
using animrt::cli::kExitUsage;

animrt::RunControls g_controls;

// The robot file's figure model, loaded (so a model that does not load is an
// error of the robot file), or null when it names none.
std::unique_ptr<animrt::sim::MujocoFigure> load_figure(const animrt::RobotConfig& config) {
  if (config.model.empty()) return nullptr;
  std::vector<std::string> names;
  for (const auto& joint : config.joints) names.push_back(joint.name);
  return std::make_unique<animrt::sim::MujocoFigure>(config.model, names, config.model_where);
}

// A gait with `balance:` plays its reflex through the legs of the robot's
// model (the loader has made sure it names one).
void attach_legs(animrt::LoadedRobot& robot) {
  if (!robot.balanced) return;
  std::vector<std::string> names;
  for (const auto& joint : robot.config.joints) names.push_back(joint.name);
  robot.balanced->attach(std::make_unique<animrt::sim::MujocoLegModel>(robot.config.model, names,
                                                                       robot.config.model_where));
}

int cmd_validate(const std::string& path, const std::string& cues_path) {
  animrt::LoadedRobot robot = animrt::load_robot(path);
  load_figure(robot.config);
  attach_legs(robot);
  std::size_t devices = 0;
  for (const auto& bus : robot.config.buses) devices += bus.actuators.size();
  std::cout << path << ": ok (" << robot.config.joints.size() << " joints, "
            << robot.config.buses.size() << " bus" << (robot.config.buses.size() == 1 ? "" : "es")
            << ", " << devices << " devices, " << animrt::describe_motion(robot.config.motion)
            << ")\n";
  for (const std::string& warning : robot.warnings) std::cout << "warning: " << warning << "\n";
  // What stops the figure if animrt itself dies, where the user must know.
  for (const std::string& note : animrt::device_guard_notes(robot.config)) {
    std::cout << note << "\n";
  }
  if (cues_path.empty()) return kExitOk;
  // The cue file as serve loads it, against this robot's joints.
  const animrt::LoadedCues cues = animrt::load_cues(cues_path, robot.config);
  std::cout << cues_path << ": ok (" << cues.cues.size() << " cue"
            << (cues.cues.size() == 1 ? "" : "s") << ", idle "
            << cues.cues[static_cast<std::size_t>(cues.idle)].name << ")\n";
  for (const std::string& warning : cues.warnings) std::cout << "warning: " << warning << "\n";
  return kExitOk;
}

struct RunArgs {
  std::string config;
  std::string backend = "sim";
  double duration = 0.0;
  std::string telemetry;
  std::string record;
  std::string summary_json;
  bool lockstep = false;
  bool no_realtime = false;
  bool no_audio = false;
  std::string physics;    // MJCF model behind the simulated servos
  std::string herd;       // scene file: the robot is one agent of this herd
  std::string agent;      // which one
  std::string dashboard;  // HOST:PORT, empty = none
  bool dashboard_remote = false;
  double dashboard_rate = 30.0;
  std::string dashboard_www = animrt::cli::dashboard_www_dir();
};

// Options that need one another or the simulated backend: a usage error
// (logged) when they do not go together.
bool run_args_go_together(const RunArgs& args) {
  if (args.lockstep && args.backend != "sim") {
    spdlog::error("--lockstep needs --backend sim (hardware runs in real time)");
    return false;
  }
  if (!args.physics.empty() && args.backend != "sim") {
    spdlog::error("--physics needs --backend sim (it replaces the simulated servos' motors)");
    return false;
  }
  if (args.herd.empty() != args.agent.empty()) {
    spdlog::error("--herd and --agent go together: the scene and which of its agents the robot is");
    return false;
  }
  return true;
}

// --dashboard: where and how it serves; the figure adds what it knows.
animrt::DashboardSetup dashboard_setup(const RunArgs& args, const std::pair<std::string, int>& at,
                                       const animrt::Figure& figure,
                                       animrt::FigureKinematics* model) {
  animrt::DashboardSetup setup;
  setup.host = at.first;
  setup.port = at.second;
  setup.remote = args.dashboard_remote;
  setup.rate_hz = args.dashboard_rate;
  setup.www_dir = args.dashboard_www;
  // A herd steers the gait itself (and the steering mailbox takes one writer).
  if (args.herd.empty()) setup.steering = figure.steering();
  setup.duration_s = args.duration;
  setup.figure = model;
  return setup;
}

int cmd_run(const RunArgs& args) {
  // The dashboard's address is a usage error before any file is read.
  const animrt::cli::DashboardAddress address =
      animrt::cli::check_dashboard_address(args.dashboard, args.dashboard_remote);
  if (!address.ok) return kExitUsage;
  const std::pair<std::string, int> dashboard_at =
      address.at.value_or(std::pair<std::string, int>{});
  animrt::cli::run_herd_here(args.herd);
  animrt::LoadedRobot robot = animrt::load_robot(args.config);
  attach_legs(robot);
  // The figure the dashboard draws: the robot file's model, or else the physics model.
  std::unique_ptr<animrt::sim::MujocoFigure> figure_model = load_figure(robot.config);
  if (!figure_model && !args.physics.empty() && !args.dashboard.empty()) {
    animrt::RobotConfig with_physics = robot.config;
    with_physics.model = args.physics;
    with_physics.model_where = animrt::Location{args.physics, 0, 0};
    figure_model = load_figure(with_physics);
  }
  // Opened before anything moves: a summary that cannot be written is found
  // now, not after the run.
  animrt::cli::OutputFile summary_out;
  if (!animrt::cli::open_summary_json(summary_out, args.summary_json)) return kExitUsage;
  if (!run_args_go_together(args)) return kExitUsage;

  animrt::HardwareBackend hardware;
  animrt::SimulatedBackend simulated(animrt::SimulatedBackend::Settings{args.physics, nullptr});
  animrt::FigureBackend& backend =
      args.backend == "sim" ? static_cast<animrt::FigureBackend&>(simulated) : hardware;
  animrt::FigureOptions figure_options;
  figure_options.lockstep = args.lockstep;
  figure_options.log = [](const std::string& line) { spdlog::info("{}", line); };
  // A show's sound track plays on its own thread, started with the motion.
  if (!args.no_audio) {
    figure_options.audio_sink = [](int rate) { return animrt::open_alsa_sink("default", rate); };
  }
  figure_options.warn = [](const std::string& line) { spdlog::warn("{}", line); };
  animrt::Figure figure(std::move(robot), backend, figure_options);

  std::unique_ptr<animrt::cli::RunHerd> herd =
      animrt::cli::join_run_herd(args.herd, args.agent, figure, simulated, g_controls);

  animrt::RunOptions options = figure.run_options();
  options.duration_s = args.duration;
  options.request_realtime = !args.no_realtime;
  options.telemetry_path = args.telemetry;
  options.record_path = args.record;
  options.controls = &g_controls;
  options.log = [](const std::string& message) { spdlog::info("{}", message); };
  if (herd) options.on_motion_start = [&herd](animrt::Nanos t0) { herd->start(t0); };

  // The dashboard serves before the start ramp, so its line comes first.
  if (!args.dashboard.empty()) {
    animrt::DashboardSetup setup = dashboard_setup(args, dashboard_at, figure, figure_model.get());
    std::cout << "dashboard: " << figure.serve_dashboard(std::move(setup), g_controls).url() << '\n'
              << std::flush;
  }
  animrt::cli::start_fault_injection();
  animrt::RunSummary summary = figure.run(options);
  if (herd) herd->stop();
  std::cout << animrt::format_summary(summary);
  if (herd) std::cout << herd->report() << '\n';
  const int code = animrt::cli::write_summary_json(
      summary_out, args.summary_json, animrt::to_json(summary).dump(2) + '\n', summary.exit_code());
  std::cout << std::flush;
  return code;
}

// The run subcommand and its options, parsed into `run_args`.
CLI::App* add_run_subcommand(CLI::App& app, RunArgs& run_args) {
  auto* run = app.add_subcommand("run", "Run a robot's motion on hardware or simulated devices");
  run->add_option("CONFIG", run_args.config, "robot file (YAML)")->required();
  run->add_option("--backend", run_args.backend, "sim (simulated devices on ptys) or hardware")
      ->check(CLI::IsMember({"sim", "hardware"}))
      ->capture_default_str();
  run->add_option("--duration", run_args.duration,
                  "seconds of motion, then ramp home (0 = until Ctrl-C)")
      ->check(animrt::cli::kRunDuration);
  run->add_option("--telemetry", run_args.telemetry, "write per-cycle CSV telemetry to this file")
      ->check(animrt::cli::kOutputFile);
  run->add_option("--record", run_args.record,
                  "record the run as MCAP to this file: joint states, events, loop statistics, "
                  "device status (Foxglove, the mcap CLI, animrt view)")
      ->check(animrt::cli::kOutputFile);
  run->add_option("--summary-json", run_args.summary_json, "write the run summary as JSON")
      ->check(animrt::cli::kOutputFile);
  run->add_flag("--lockstep", run_args.lockstep,
                "simulated clock: run as fast as the devices answer (sim backend only)");
  run->add_flag("--no-realtime", run_args.no_realtime, "do not request SCHED_FIFO or mlockall");
  run->add_flag("--no-audio", run_args.no_audio, "do not play the show's sound track");
  run->add_option("--physics", run_args.physics,
                  "MuJoCo model (MJCF) behind the simulated servos; the summary reports distance, "
                  "speed and falls (sim backend, dynamixel2 buses)");

  run->add_option("--dashboard", run_args.dashboard,
                  "serve the dashboard at HOST:PORT (port 0: a free one; loopback only unless "
                  "--dashboard-remote); prints its URL with the run's token");
  run->add_flag("--dashboard-remote", run_args.dashboard_remote,
                "let the dashboard listen on an address other machines can reach");
  run->add_option("--dashboard-rate", run_args.dashboard_rate, "dashboard stream rate in Hz")
      ->check(animrt::cli::FiniteRange(0.5, 200.0));
  run->add_option("--dashboard-www", run_args.dashboard_www, "folder of the dashboard's page")
      ->check(CLI::ExistingDirectory);

  run->add_option("--herd", run_args.herd,
                  "herd scene (YAML): the robot walks as one of its agents (needs --agent)");
  run->add_option("--agent", run_args.agent,
                  "the herd agent the robot is, GROUP.INDEX (e.g. red.0)");
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  auto logger = spdlog::stderr_color_mt("animrt");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("%^[%l]%$ %v");

  // Before any command runs: a fatal error switches torque off first
  // (emergency_stop.hpp), and a write to a pipe or socket whose reader left
  // fails with EPIPE instead of killing the process (a dashboard whose
  // browser closed; run and sim take SIGPIPE as a stop below).
  animrt::install_fatal_error_handlers();
  animrt::cli::remember_argv(argv);
  signal(SIGPIPE, SIG_IGN);

  CLI::App app{"animrt: real-time motion for animatronic figures"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "animrt " ANIMRT_VERSION);
  app.option_defaults()->always_capture_default();  // every --help shows the defaults

  std::string validate_path, validate_cues;
  auto* validate = app.add_subcommand("validate", "Check a robot file and the files it names");
  validate->add_option("FILE", validate_path, "robot file (YAML)")->required();
  validate->add_option("--cues", validate_cues,
                       "also check this cue file (animrt serve's) against the robot");

  RunArgs run_args;
  auto* run = add_run_subcommand(app, run_args);

  animrt::cli::add_sim_command(app);
  animrt::cli::add_tool_commands(app);
  animrt::cli::add_view_command(app);
  animrt::cli::add_scan_command(app);
  animrt::cli::add_servo_command(app);
  animrt::cli::add_calibrate_command(app);
  animrt::cli::add_record_command(app);
  animrt::cli::add_doctor_command(app);
  animrt::cli::add_serve_command(app);
  animrt::cli::hide_empty_defaults(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // evolve and head report their own result this way
  } catch (const CLI::ParseError& e) {
    // Help and version print and succeed; every other parse error is a usage
    // error (CLI11's own exit codes, 100 and up, are not ours).
    return app.exit(e) == static_cast<int>(CLI::ExitCodes::Success) ? kExitOk : kExitUsage;
  }
  animrt::cli::install_stop_signals(g_controls);
  try {
    if (*validate) return cmd_validate(validate_path, validate_cues);
    if (*run) return cmd_run(run_args);
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
