#include "view_command.hpp"

#include <pthread.h>
#include <signal.h>

#include <iostream>
#include <memory>
#include <string>

#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/telemetry_replay.hpp"
#include "animrt/sim/mujoco/mujoco_figure.hpp"
#include "data_dir.hpp"
#include "option_checks.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct ViewArgs {
  std::string csv;
  std::string robot;
  std::string dashboard = "127.0.0.1:0";
  bool remote = false;
  double rate = 30.0;
  std::string www = dashboard_www_dir();
};

int run_view(const ViewArgs& args) {
  const auto [host, port] = parse_host_port(args.dashboard);
  if (!args.remote && !is_loopback_host(host)) {
    std::cerr << "error: --dashboard: " << host
              << " is not a loopback address; serving other machines needs --dashboard-remote\n";
    return kExitUsage;
  }
  const TelemetryRecording recording = load_telemetry(args.csv);
  std::unique_ptr<RobotConfig> robot;
  std::unique_ptr<sim::MujocoFigure> figure;
  if (!args.robot.empty()) {
    robot = std::make_unique<RobotConfig>(load_robot_config(args.robot));
    if (!robot->model.empty()) {
      figure =
          std::make_unique<sim::MujocoFigure>(robot->model, recording.joints, robot->model_where);
    }
  }
  const RobotModel model = replay_model(recording, robot.get());

  // Ctrl-C (or any other stop signal: stop_signals.hpp) ends the viewer:
  // the signals are taken by sigwait below, so every thread started from
  // here on leaves them blocked.
  sigset_t signals;
  sigemptyset(&signals);
  add_counting_stop_signals(signals);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  RunMonitor monitor(model);
  TelemetryReplay replay(recording, monitor);
  RunControls controls;  // a replay takes none; the server answers 409
  DashboardSetup setup;
  setup.host = host;
  setup.port = port;
  setup.remote = args.remote;
  setup.rate_hz = args.rate;
  setup.www_dir = args.www;
  setup.robot = robot ? robot->name : recording.file;
  setup.backend = "replay";
  if (robot && !model.buses.empty()) {
    for (const auto& bus : robot->buses) setup.bus_protocols.push_back(bus.protocol);
  }
  setup.motion_kind = "replay";
  setup.motion_name = recording.file;
  setup.duration_s = recording.t.back() - recording.t.front();
  setup.figure = figure.get();
  setup.replay = true;
  setup.replay_start_s = recording.t.front();
  setup.replay_end_s = recording.t.back();
  setup.replay_times_s = recording.t;
  setup.seek = [&replay](double t, bool playing) { replay.seek(t, playing); };
  DashboardServer server(monitor, controls, setup);
  std::cout << "dashboard: " << server.url() << '\n' << std::flush;
  int signal = 0;
  sigwait(&signals, &signal);
  server.stop();
  return 0;
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand(
      "view",
      "Replay a recorded run (animrt run --telemetry or --record) on the dashboard, with a time "
      "slider");
  cmd->add_option("TELEMETRY", args->csv,
                  "telemetry CSV of animrt run --telemetry, or MCAP of animrt run --record")
      ->required();
  cmd->add_option("--robot", args->robot,
                  "the robot file of the run: limits, buses and the figure's model");
  cmd->add_option("--dashboard", args->dashboard, "HOST:PORT to serve at");
  cmd->add_flag("--dashboard-remote", args->remote,
                "let the dashboard listen on an address other machines can reach");
  cmd->add_option("--dashboard-rate", args->rate, "stream rate in Hz")
      ->check(FiniteRange(0.5, 200.0));
  cmd->add_option("--dashboard-www", args->www, "folder of the dashboard's page")
      ->check(CLI::ExistingDirectory);
  set_subcommand_body(cmd, [args] { return run_view(*args); });
}

}  // namespace animrt::cli
