#include "serve_command.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "animrt/core/error.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/osc_receiver.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/run_summary.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "dashboard_address.hpp"
#include "data_dir.hpp"
#include "fault_injection.hpp"
#include "option_checks.hpp"
#include "output_file.hpp"
#include "serve_dmx.hpp"
#include "serve_sound.hpp"
#include "serve_triggers.hpp"
#include "service_notify.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct ServeArgs {
  std::string robot;
  std::string cues;
  std::string backend = "sim";
  double duration = 0.0;
  bool lockstep = false;
  bool no_realtime = false;
  std::string osc_bind = "127.0.0.1";
  int osc_port = 9000;
  bool no_osc = false;
  DmxArgs dmx;            // Art-Net and sACN
  TriggerArgs triggers;   // LTC and MIDI
  SoundArgs sound;        // the cues' sound tracks
  std::string dashboard;  // HOST:PORT, empty = none
  bool dashboard_remote = false;
  std::string summary_json;  // empty = none
};

// Written by the signal handlers, OSC's /stop and the dashboard; read by the cycle.
RunControls serve_controls;

// What an OSC message asks: /cue/NAME, /stop, /pause (an argument 0 or
// false resumes), /resume. False for any other address, and for a /pause
// whose argument is NaN (counted as unknown).
bool answer_osc(const OscMessage& message, const std::vector<std::string>& cues,
                CueRequests& requests) {
  const std::string& address = message.address;
  if (address == "/stop") {
    serve_controls.stop.store(true);
    return true;
  }
  if (address == "/pause") {
    // No number pauses, 0 (or false) resumes; a NaN asks nothing.
    if (!message.numbers.empty() && std::isnan(message.numbers.front())) return false;
    requests.pause(message.numbers.empty() || message.numbers.front() != 0.0);
    return true;
  }
  if (address == "/resume") {
    requests.pause(false);
    return true;
  }
  constexpr std::string_view kCue = "/cue/";
  if (address.rfind(kCue, 0) != 0) return false;
  const auto found = std::find(cues.begin(), cues.end(), address.substr(kCue.size()));
  if (found == cues.end()) return false;
  requests.cue(static_cast<int>(found - cues.begin()));
  return true;
}

// What was played and what the triggers sent, after the run's summary.
// The cue requests' counts, read once for both reports.
struct CueCounts {
  std::uint64_t posted = 0;
  std::uint64_t taken = 0;
};

void print_cue_report(const CuePlayer& player, const CueCounts& requests, const OscReceiver* osc,
                      const ServeDmx& dmx, const ServeTriggers& triggers) {
  std::cout << "cues started:";
  for (std::size_t c = 0; c < player.cues().size(); ++c) {
    std::cout << ' ' << player.cues()[c].name << ' ' << player.starts(static_cast<int>(c));
  }
  std::cout << '\n'
            << "cue requests: " << requests.posted << " posted, " << requests.taken
            << " taken by the cycle (the rest replaced by a newer one first), " << player.deferred()
            << " cycles waited for a crossfade to end\n";
  if (const TransitionWorker* worker = player.transition_worker()) {
    std::cout << "learned transitions: " << player.learned_played() << " played, "
              << player.learned_late() << " crossfaded (not computed within "
              << player.learned_wait_s() * 1000.0 << " ms), " << player.learned_unusable()
              << " crossfaded (unusable), compute " << worker->max_compute().count() / 1000
              << " us at most\n";
  }
  if (player.sound_commands_lost() > 0) {
    std::cout << "sound: " << player.sound_commands_lost()
              << " commands lost (a player had fallen behind)\n";
  }
  if (osc) {
    std::cout << "osc: " << osc->packets() << " packets, " << osc->messages() << " messages, "
              << osc->malformed() << " malformed, " << osc->unknown() << " unknown addresses\n";
  }
  dmx.report(std::cout);
  triggers.report(std::cout);
}

// --summary-json: the run's summary and the cues' counts.
std::string cue_summary_json(const RunSummary& summary, const CuePlayer& player,
                             const CueCounts& requests) {
  nlohmann::json j = to_json(summary);
  nlohmann::json started = nlohmann::json::object();
  for (std::size_t c = 0; c < player.cues().size(); ++c)
    started[player.cues()[c].name] = player.starts(static_cast<int>(c));
  j["cues_started"] = started;
  j["cue_requests"] = {
      {"posted", requests.posted}, {"taken", requests.taken}, {"cycles_waited", player.deferred()}};
  if (const TransitionWorker* worker = player.transition_worker()) {
    j["learned_transitions"] = {
        {"played", player.learned_played()},
        {"late", player.learned_late()},
        {"unusable", player.learned_unusable()},
        {"max_compute_s", 1e-9 * static_cast<double>(worker->max_compute().count())}};
  }
  return j.dump(2) + '\n';
}

// --dashboard: the run's page, which also asks for cues and pauses them.
void serve_dashboard(Figure& figure, const std::pair<std::string, int>& at, bool remote,
                     const CuePlayer& player, CueRequests& requests) {
  DashboardSetup setup;
  setup.host = at.first;
  setup.port = at.second;
  setup.remote = remote;
  setup.www_dir = dashboard_www_dir();
  setup.cue = [&player, &requests](const std::string& name) {
    const int cue = find_cue(player.cues(), name);
    if (cue >= 0) requests.cue(cue);
    return cue >= 0;
  };
  setup.pause_cues = [&requests](bool paused) { requests.pause(paused); };
  std::cout << "dashboard: " << figure.serve_dashboard(std::move(setup), serve_controls).url()
            << '\n'
            << std::flush;
}

// The triggers' receivers, each on its own thread, listening before the figure moves.
std::unique_ptr<OscReceiver> start_osc(const ServeArgs& args, const CuePlayer& playing,
                                       CueRequests& requests) {
  if (args.no_osc) return nullptr;
  // The names are the receiver's own: its thread may outlive the player.
  std::vector<std::string> names;
  for (const Cue& cue : playing.cues()) names.push_back(cue.name);
  auto osc = std::make_unique<OscReceiver>(
      args.osc_bind, args.osc_port,
      [names = std::move(names), &requests](const OscMessage& message) {
        return answer_osc(message, names, requests);
      });
  std::cout << "osc: listening on " << args.osc_bind << ':' << osc->port() << '\n' << std::flush;
  return osc;
}

int serve(const ServeArgs& args) {
  install_stop_signals(serve_controls);
  if (args.lockstep && args.backend != "sim") {
    spdlog::error("--lockstep needs --backend sim (hardware runs in real time)");
    return kExitUsage;
  }
  const DashboardAddress address = check_dashboard_address(args.dashboard, args.dashboard_remote);
  if (!address.ok) return kExitUsage;
  OutputFile summary_out;  // opened before anything moves
  if (!open_summary_json(summary_out, args.summary_json)) return kExitUsage;
  LoadedRobot robot = load_robot(args.robot);
  // Every cue file and what it names is valid before any device starts.
  LoadedCues loaded = load_cues(args.cues, robot.config);
  robot.warnings.insert(robot.warnings.end(), loaded.warnings.begin(), loaded.warnings.end());
  CueRequests requests;
  auto player = std::make_unique<CuePlayer>(std::move(loaded.cues), loaded.idle,
                                            robot.config.joints, requests);
  if (TransitionWorker* worker = player->transition_worker()) {
    worker->set_delay(
        std::chrono::nanoseconds(static_cast<std::int64_t>(transition_delay_for_test() * 1e9)));
  }
  const CuePlayer& playing = *player;
  // Declared before the figure: the players outlive the cue player that tells them.
  ServeSound sound(args.sound, args.lockstep, *player);
  robot.motion = std::move(player);
  robot.steering.reset();
  const std::unique_ptr<OscReceiver> osc = start_osc(args, playing, requests);
  const ServeDmx dmx(args.dmx, loaded, requests, robot.motion, robot.config.joints);
  ServeTriggers triggers(args.triggers, loaded, requests);

  HardwareBackend hardware;
  SimulatedBackend simulated(SimulatedBackend::Settings{});
  FigureBackend& backend =
      args.backend == "sim" ? static_cast<FigureBackend&>(simulated) : hardware;
  FigureOptions figure_options;
  figure_options.lockstep = args.lockstep;
  figure_options.log = [](const std::string& line) { spdlog::info("{}", line); };
  figure_options.warn = [](const std::string& line) { spdlog::warn("{}", line); };
  Figure figure(std::move(robot), backend, figure_options);
  if (address.at) serve_dashboard(figure, *address.at, args.dashboard_remote, playing, requests);

  RunOptions options = figure.run_options();
  options.duration_s = args.duration;
  options.request_realtime = !args.no_realtime;
  options.controls = &serve_controls;
  options.log = [](const std::string& message) { spdlog::info("{}", message); };
  // Under systemd: ready after the start ramp, the watchdog fed by the loop's cycles.
  RunHeartbeat heartbeat;
  options.heartbeat = &heartbeat;
  std::optional<ServiceNotifier> notifier(std::in_place, heartbeat);
  options.on_motion_start = [&triggers, &sound](Nanos t0) {
    sound.start(t0);
    triggers.begin();
  };
  options.on_motion_end = [&sound, &requests] {
    sound.stop();
    requests.close();  // what came later is not the run's
  };
  start_fault_injection();
  const RunSummary summary = figure.run(options);
  // Closed at the motion's end; a request that passed the check just before
  // may still count, so both reports read the counts once, here.
  const CueCounts counts{requests.posted(), requests.taken()};
  slow_exit_for_test();
  std::cout << format_summary(summary);
  print_cue_report(playing, counts, osc.get(), dmx, triggers);
  const int code =
      write_summary_json(summary_out, args.summary_json, cue_summary_json(summary, playing, counts),
                         summary.exit_code());
  std::cout << std::flush;
  // The watchdog is fed up to here: the figure was released, and writing
  // the summary may take seconds on a loaded machine.
  notifier.reset();
  return code;
}

}  // namespace

void add_serve_command(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  auto* cmd = app.add_subcommand(
      "serve", "Serve a figure: play a cue file's idle cue and triggered cues until stopped");
  cmd->add_option("ROBOT", args->robot, "robot file (YAML)")->required();
  cmd->add_option("--cues", args->cues, "cue file (YAML)")->required();
  cmd->add_option("--backend", args->backend, "sim (simulated devices on ptys) or hardware")
      ->check(CLI::IsMember({"sim", "hardware"}));
  cmd->add_option("--duration", args->duration, "seconds, then ramp home (0 = until stopped)")
      ->check(kRunDuration);
  cmd->add_flag("--lockstep", args->lockstep,
                "simulated clock: run as fast as the devices answer (sim backend only)");
  cmd->add_flag("--no-realtime", args->no_realtime, "do not request SCHED_FIFO or mlockall");
  cmd->add_option("--osc-bind", args->osc_bind,
                  "address OSC listens on (loopback unless another is given)");
  cmd->add_option("--osc-port", args->osc_port, "UDP port for OSC (0: a free one, printed)")
      ->check(CLI::Range(0, 65535));
  cmd->add_flag("--no-osc", args->no_osc, "take no OSC triggers");
  add_dmx_options(cmd, args->dmx);
  add_trigger_options(cmd, args->triggers);
  add_sound_options(cmd, args->sound);
  cmd->add_option("--dashboard", args->dashboard,
                  "serve the dashboard at HOST:PORT (as run's; POST /api/cue asks for a cue)");
  cmd->add_flag("--dashboard-remote", args->dashboard_remote,
                "let the dashboard listen on an address other machines can reach");
  cmd->add_option("--summary-json", args->summary_json,
                  "write the run's summary and the cues' counts as JSON")
      ->check(kOutputFile);
  set_subcommand_body(cmd, [args]() -> int {
    try {
      return serve(*args);
    } catch (const DeviceError& e) {
      std::cerr << "error: " << e.what() << '\n';
      return kExitDeviceError;
    }
  });
}

}  // namespace animrt::cli
