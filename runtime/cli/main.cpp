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
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>

#include "animrt/controllers/show/show_audio.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/emergency_stop.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/mujoco/mujoco_figure.hpp"
#include "animrt/sim/mujoco/mujoco_physics.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "dashboard_address.hpp"
#include "evolve_command.hpp"
#include "fault_injection.hpp"
#include "gait_command.hpp"
#include "head_command.hpp"
#include "herd_command.hpp"
#include "herd_driver.hpp"
#include "seq_command.hpp"
#include "seq_corpus_command.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"
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

int cmd_validate(const std::string& path) {
  animrt::LoadedRobot robot = animrt::load_robot(path);
  load_figure(robot.config);
  std::size_t devices = 0;
  for (const auto& bus : robot.config.buses) devices += bus.actuators.size();
  std::cout << path << ": ok (" << robot.config.joints.size() << " joints, "
            << robot.config.buses.size() << " bus" << (robot.config.buses.size() == 1 ? "" : "es")
            << ", " << devices << " devices, " << animrt::describe_motion(robot.config.motion)
            << ")\n";
  // What stops the figure if animrt itself dies, where the user must know.
  for (const std::string& note : animrt::device_guard_notes(robot.config)) {
    std::cout << note << "\n";
  }
  return kExitOk;
}

// Longest --duration accepted: a year, far past any show.
constexpr double kMaxDurationS = 365.0 * 24 * 3600;

// --duration: a finite number of seconds, 0 (until Ctrl-C) up to a year.
// The message quotes the argument as given, not CLI11's conversion of it.
CLI::Validator duration_validator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        const char* end = text.data() + text.size();
        const auto [stop, ec] = std::from_chars(text.data(), end, value);
        const std::string expected = "expected seconds from 0 (until Ctrl-C) to " +
                                     std::to_string(static_cast<long long>(kMaxDurationS)) +
                                     ", found " + animrt::quote(text);
        if (ec != std::errc() || stop != end || text.empty()) return expected;
        if (!std::isfinite(value) || value < 0.0 || value > kMaxDurationS) return expected;
        return "";
      },
      "SECONDS");
}

// --summary-json's file: opened before anything moves (a summary that
// cannot be written is found then), written once at the end, every failure
// (a full disk, /dev/full, a close that fails) kept with its errno.
struct SummaryFile {
  int fd = -1;
  int error = 0;
  ~SummaryFile() {
    if (fd >= 0) ::close(fd);
  }
  bool is_open() const { return fd >= 0; }
  bool open(const std::string& path) {
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) error = errno;
    return fd >= 0;
  }
  bool write(const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
      } else if (n < 0 && errno == EINTR) {
        continue;
      } else {
        error = n < 0 ? errno : EIO;
        return false;
      }
    }
    const int closed = ::close(fd);
    fd = -1;
    if (closed != 0) error = errno;
    return closed == 0;
  }
};

struct RunArgs {
  std::string config;
  std::string backend = "sim";
  double duration = 0.0;
  std::string telemetry;
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
  std::string dashboard_www = ANIMRT_DASHBOARD_WWW;
};

// The show files a motion plays (a show, or show layers).
void collect_shows(const animrt::MotionConfig& motion, std::vector<std::string>& out) {
  if (motion.type == "show") out.push_back(motion.file);
  for (const auto& layer : motion.layers) collect_shows(layer, out);
}

int cmd_run(const RunArgs& args) {
  // The dashboard's address is a usage error before any file is read.
  const animrt::cli::DashboardAddress address =
      animrt::cli::check_dashboard_address(args.dashboard, args.dashboard_remote);
  if (!address.ok) return kExitUsage;
  const std::pair<std::string, int> dashboard_at =
      address.at.value_or(std::pair<std::string, int>{});
  animrt::LoadedRobot robot = animrt::load_robot(args.config);
  // The figure: the robot file's model, or else the physics model.
  std::unique_ptr<animrt::sim::MujocoFigure> figure = load_figure(robot.config);
  if (!figure && !args.physics.empty() && !args.dashboard.empty()) {
    animrt::RobotConfig with_physics = robot.config;
    with_physics.model = args.physics;
    with_physics.model_where = animrt::Location{args.physics, 0, 0};
    figure = load_figure(with_physics);
  }
  // What the dashboard tells of the run, taken before the runner owns the config.
  animrt::DashboardSetup dashboard_setup;
  if (!args.dashboard.empty()) {
    dashboard_setup.host = dashboard_at.first;
    dashboard_setup.port = dashboard_at.second;
    dashboard_setup.remote = args.dashboard_remote;
    dashboard_setup.rate_hz = args.dashboard_rate;
    dashboard_setup.www_dir = args.dashboard_www;
    dashboard_setup.robot = robot.config.name;
    dashboard_setup.backend = args.backend;
    for (const auto& bus : robot.config.buses)
      dashboard_setup.bus_protocols.push_back(bus.protocol);
    dashboard_setup.motion_kind = robot.config.motion.type;
    dashboard_setup.motion_name = std::filesystem::path(robot.config.motion.file).stem().string();
    // A herd steers the gait itself (and the steering mailbox takes one writer).
    if (args.herd.empty()) dashboard_setup.steering = robot.steering;
    const animrt::ShowPosition show = robot.motion->show_position(0.0);
    dashboard_setup.show = show.show;
    dashboard_setup.show_duration_s = show.duration_s;
    dashboard_setup.duration_s = args.duration;
    dashboard_setup.figure = figure.get();
  }
  // Opened before anything moves: a summary that cannot be written is found
  // now, not after the run.
  SummaryFile summary_out;
  if (!args.summary_json.empty() && !summary_out.open(args.summary_json)) {
    spdlog::error("--summary-json: cannot write {}: {}", args.summary_json,
                  std::strerror(summary_out.error));
    return kExitUsage;
  }
  if (args.lockstep && args.backend != "sim") {
    spdlog::error("--lockstep needs --backend sim (hardware runs in real time)");
    return kExitUsage;
  }
  if (!args.physics.empty() && args.backend != "sim") {
    spdlog::error("--physics needs --backend sim (it replaces the simulated servos' motors)");
    return kExitUsage;
  }
  animrt::ManualClock lockstep_clock;
  animrt::MonotonicClock wall_clock;
  std::unique_ptr<animrt::sim::MujocoJointPhysics> physics;  // outlives the devices below
  std::vector<std::unique_ptr<animrt::SimulatedBus>> simulated;
  if (args.backend == "sim") {
    const animrt::Clock& clock = args.lockstep ? static_cast<const animrt::Clock&>(lockstep_clock)
                                               : static_cast<const animrt::Clock&>(wall_clock);
    if (!args.physics.empty()) {
      physics = std::make_unique<animrt::sim::MujocoJointPhysics>(args.physics, robot.config.joints,
                                                                  robot.config.file, clock.now());
      spdlog::info("physics: {} drives the simulated servos", args.physics);
    }
    simulated = animrt::start_simulated_devices(robot.config.buses, clock, physics.get());
    for (const auto& sim : simulated) spdlog::info("simulated devices: {}", sim->describe());
  }
  if (args.lockstep) animrt::widen_timeouts_for_lockstep(robot.config.buses);
  std::vector<std::unique_ptr<animrt::ActuatorBus>> buses;
  for (const auto& bus : robot.config.buses) buses.push_back(animrt::make_bus(bus));

  if (args.herd.empty() != args.agent.empty()) {
    spdlog::error("--herd and --agent go together: the scene and which of its agents the robot is");
    return kExitUsage;
  }
  std::unique_ptr<animrt::cli::EmbodiedHerd> herd;
  if (!args.herd.empty()) {
    const animrt::Clock& run_clock = args.lockstep
                                         ? static_cast<const animrt::Clock&>(lockstep_clock)
                                         : static_cast<const animrt::Clock&>(wall_clock);
    herd = std::make_unique<animrt::cli::EmbodiedHerd>(args.herd, args.agent, run_clock, g_controls,
                                                       physics.get());
    spdlog::info("herd: {} steers the robot as agent {}", args.herd, args.agent);
  }

  animrt::RunOptions options;
  options.duration_s = args.duration;
  options.lockstep_clock = args.lockstep ? &lockstep_clock : nullptr;
  options.request_realtime = !args.no_realtime;
  options.telemetry_path = args.telemetry;
  options.controls = &g_controls;
  options.backend_name = args.backend;
  options.log = [](const std::string& message) { spdlog::info("{}", message); };
  options.raise_device_threads = [&simulated](int priority) {
    return animrt::raise_simulated_devices(simulated, priority);
  };

  // A show's sound track plays on its own thread, started with the motion.
  std::vector<std::unique_ptr<animrt::ShowAudioPlayer>> audio;
  if (!args.no_audio) {
    std::vector<std::string> shows;
    collect_shows(robot.config.motion, shows);
    audio = animrt::open_show_audio(
        shows, args.lockstep, [](int rate) { return animrt::open_alsa_sink("default", rate); },
        wall_clock, [](const std::string& message) { spdlog::warn("{}", message); });
  }
  options.on_motion_start = [&audio, &herd, p = physics.get()](animrt::Nanos t0) {
    for (auto& player : audio) player->start(t0);
    if (herd) herd->start(t0);
    if (p) p->mark_motion_start();
  };
  options.on_motion_end = [&audio, p = physics.get()] {
    for (auto& player : audio) player->stop();
    if (p) p->mark_motion_end();
  };
  // The sound track follows the show's pause, seek and play.
  if (!audio.empty()) {
    options.on_show_command = [&audio](const animrt::ShowCommand& command, double t) {
      for (auto& player : audio) player->control(command, t);
    };
  }

  animrt::Runner runner(std::move(robot.config), std::move(buses), std::move(robot.motion));
  // The dashboard serves before the start ramp, so its line comes first.
  std::unique_ptr<animrt::RunMonitor> monitor;
  std::unique_ptr<animrt::DashboardServer> dashboard;
  if (!args.dashboard.empty()) {
    monitor = std::make_unique<animrt::RunMonitor>(runner.model());
    dashboard = std::make_unique<animrt::DashboardServer>(*monitor, g_controls, dashboard_setup);
    options.monitor = monitor.get();
    std::cout << "dashboard: " << dashboard->url() << '\n' << std::flush;
  }
  animrt::cli::start_fault_injection();
  animrt::RunSummary summary = runner.run(options);
  if (dashboard) dashboard->stop();
  if (herd) herd->stop();
  if (physics) {
    const animrt::sim::PhysicsMeasures m = physics->measures();
    animrt::PhysicsReport report;
    report.model = m.model_file;
    report.timestep_s = m.timestep_s;
    report.simulated_s = m.simulated_s;
    report.forward_m = m.forward_m;
    report.sideways_m = m.sideways_m;
    report.motion_s = m.motion_s;
    report.motion_forward_m = m.motion_forward_m;
    report.average_speed_m_s = m.motion_s > 0 ? m.motion_forward_m / m.motion_s : 0.0;
    report.falls = m.falls;
    report.first_fall_s = m.first_fall_s;
    report.lockstep_waits_timed_out = m.lockstep_waits_timed_out;
    summary.physics = report;
  }
  const bool summary_written =
      !summary_out.is_open() || summary_out.write(animrt::to_json(summary).dump(2) + '\n');
  std::cout << animrt::format_summary(summary);
  if (herd) std::cout << herd->report() << '\n';
  int code = summary.exit_code();
  if (!summary_written) {
    std::cout << "RECORD LOST summary JSON: could not be written to " << args.summary_json << ": "
              << std::strerror(summary_out.error) << '\n';
    if (code == kExitOk) code = animrt::cli::kExitRecordLost;
  }
  std::cout << std::flush;
  return code;
}

int cmd_sim(const std::string& path) {
  animrt::LoadedRobot robot = animrt::load_robot(path);
  animrt::MonotonicClock clock;
  // Served for other programs: CAN devices go on the real interfaces.
  animrt::sim::set_can_sim_attach(animrt::sim::CanSimAttach::socketcan);
  auto simulated = animrt::start_simulated_devices(robot.config.buses, clock);
  // Just below the bus threads of an `animrt run` on this machine (loop 80,
  // buses 79), so a busy host does not make the devices miss their answers.
  for (const std::string& note :
       animrt::raise_simulated_devices(simulated, animrt::RunOptions{}.realtime_priority - 2)) {
    spdlog::warn("simulated devices: {}", note);
  }
  for (const auto& sim : simulated) std::cout << sim->describe() << '\n';
  std::cout << std::flush;
  while (!g_controls.stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return kExitOk;
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
  signal(SIGPIPE, SIG_IGN);

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
  run->add_option("--duration", run_args.duration,
                  "seconds of motion, then ramp home (0 = until Ctrl-C)")
      ->check(duration_validator());
  run->add_option("--telemetry", run_args.telemetry, "write per-cycle CSV telemetry to this file");
  run->add_option("--summary-json", run_args.summary_json, "write the run summary as JSON");
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
  run->add_option("--dashboard-rate", run_args.dashboard_rate,
                  "dashboard stream rate in Hz (default 30)")
      ->check(CLI::Range(0.5, 200.0));
  run->add_option("--dashboard-www", run_args.dashboard_www,
                  "folder of the dashboard's page (default: the source tree's)")
      ->check(CLI::ExistingDirectory);

  run->add_option("--herd", run_args.herd,
                  "herd scene (YAML): the robot walks as one of its agents (needs --agent)");
  run->add_option("--agent", run_args.agent,
                  "the herd agent the robot is, GROUP.INDEX (e.g. red.0)");

  std::string sim_path;
  auto* sim = app.add_subcommand("sim", "Serve a robot's simulated devices until Ctrl-C");
  sim->add_option("CONFIG", sim_path, "robot file (YAML)")->required();

  animrt::cli::add_evolve_command(app);
  animrt::cli::add_gait_command(app);
  animrt::cli::add_head_command(app);
  animrt::cli::add_herd_command(app);
  animrt::cli::add_view_command(app);
  auto* seq = app.add_subcommand(
      "seq", "Mesh sequences: generated corpus, deformation features, the sequence network");
  seq->require_subcommand(1);
  animrt::cli::add_seq_corpus_command(*seq);
  animrt::cli::add_seq_command(*seq);
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
