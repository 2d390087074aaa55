// The herd subcommand: load the scene, build the herd, step it to the end,
// write the CSV, the top view and the summary.

#include "herd_command.hpp"

#include <cerrno>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "animrt/controllers/herd/herd_output.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/embodied_herd.hpp"
#include "animrt/runtime/herd_dashboard.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "dashboard_address.hpp"
#include "data_dir.hpp"
#include "option_checks.hpp"
#include "output_file.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct HerdArgs {
  std::string scene;
  std::optional<double> duration;
  std::optional<std::uint64_t> seed;
  std::string out;
  std::string svg;
  std::string summary_json;
  bool quiet = false;
  std::string dashboard;  // HOST:PORT, "" for none
  bool dashboard_remote = false;
  double dashboard_speed = 1.0;
  double dashboard_rate = 30.0;
  std::string dashboard_www = animrt::cli::dashboard_www_dir();
};

nlohmann::json to_json(const herd::HerdMetrics& m, double wall_s) {
  nlohmann::json j;
  j["duration_s"] = m.duration_s;
  j["wall_s"] = wall_s;
  j["real_time_factor"] = wall_s > 0 ? m.duration_s / wall_s : 0.0;
  j["output_steps"] = m.steps;
  j["collisions"] = m.collisions;
  // Whatever was not measured is null, never a zero that looks measured.
  const auto measured = [](bool has, double v) -> nlohmann::json {
    return has ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  j["min_pair_distance_m"] = measured(m.has_pair, m.min_pair_distance_m);
  j["min_clearance_m"] = measured(m.has_pair, m.min_clearance_m);
  j["contact_stops"] = m.contact_stops;
  j["knots"] = m.knots;
  for (const herd::GroupMetrics& g : m.groups) {
    nlohmann::json k;
    k["name"] = g.name;
    k["kind"] = g.kind;
    k["agents"] = g.agents;
    k["collisions"] = g.collisions;
    k["min_pair_distance_m"] = measured(g.has_pair, g.min_pair_distance_m);
    // A standing flock or one never seen moving has no order to report.
    k["standing"] = g.standing;
    const bool ordered = !g.standing && g.order_steps > 0;
    k["order_mean"] = measured(ordered, g.order_mean);
    k["order_min"] = measured(ordered, g.order_min);
    k["speed_mean_mps"] = g.speed_mean_mps;
    if (g.leader_speed_mean_mps >= 0) k["leader_speed_mean_mps"] = g.leader_speed_mean_mps;
    k["nearest_neighbour_mean_m"] = measured(g.has_neighbour, g.nearest_neighbour_mean_m);
    if (g.leader_distance_mean_m >= 0) {
      k["leader_distance_mean_m"] = g.leader_distance_mean_m;
      k["leader_distance_max_m"] = g.leader_distance_max_m;
    }
    if (g.arrivals >= 0) {
      k["arrivals"] = g.arrivals;
      const bool any = g.arrivals > 0;
      k["time_to_goal_mean_s"] = measured(any, g.time_to_goal_mean_s);
      k["time_to_goal_max_s"] = measured(any, g.time_to_goal_max_s);
      k["time_ratio_max"] = measured(any, g.time_ratio_max);
      k["path_ratio_mean"] = measured(any, g.path_ratio_mean);
      k["path_ratio_max"] = measured(any, g.path_ratio_max);
      k["stuck"] = g.stuck;
    }
    j["groups"].push_back(k);
  }
  return j;
}

RunControls herd_signal_controls;  // a herd takes only its stop

// With a dashboard the herd walks at real time (or a multiple of it), so
// it can be watched; without one it runs as fast as it can.
std::unique_ptr<HerdDashboardServer> serve_dashboard(const HerdArgs& a,
                                                     const std::pair<std::string, int>& at,
                                                     herd::Herd& herd) {
  HerdDashboardSetup setup;
  setup.host = at.first;
  setup.port = at.second;
  setup.remote = a.dashboard_remote;
  setup.www_dir = a.dashboard_www;
  setup.speed = a.dashboard_speed;
  auto dashboard = std::make_unique<HerdDashboardServer>(herd, setup);
  std::cout << "dashboard: " << dashboard->url() << '\n' << std::flush;
  // Served, it may be left running: a stop signal ends it as the page's
  // Stop does, files written (a second one ends it at once).
  install_stop_signals(herd_signal_controls, SecondSignal::end_process);
  return dashboard;
}

// Steps the herd to its end (or a stop), calling `output` at the output
// rate; with a dashboard, paced to its speed and published at its rate.
void step_herd(const HerdArgs& a, herd::Herd& herd, HerdDashboardServer* dashboard,
               const std::function<void()>& output, std::chrono::steady_clock::time_point start) {
  const herd::HerdScene& s = herd.scene();
  const long steps = std::lround(s.duration_s / s.step_s);
  const long steps_per_output = std::max(1L, std::lround(1.0 / (s.output_hz * s.step_s)));
  auto last_progress = start;
  const auto publish_period = std::chrono::duration<double>(1.0 / a.dashboard_rate);
  auto last_publish = start;
  for (long k = 1; k <= steps; ++k) {
    if (dashboard) {
      if (dashboard->stop_requested() || herd_signal_controls.stop.load()) break;
      const auto due =
          start +
          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
              std::chrono::duration<double>(static_cast<double>(k) * s.step_s / a.dashboard_speed));
      std::this_thread::sleep_until(due);
    }
    herd.step();
    if (k % steps_per_output == 0 || k == steps) output();
    if (dashboard && std::chrono::steady_clock::now() - last_publish >= publish_period) {
      last_publish = std::chrono::steady_clock::now();
      dashboard->publish(herd);
    }
    const auto now = std::chrono::steady_clock::now();
    if (!a.quiet && now - last_progress > std::chrono::seconds(2)) {
      last_progress = now;
      const double wall = std::chrono::duration<double>(now - start).count();
      std::cout << "  t " << herd.time() << " s of " << s.duration_s << " s, " << herd.time() / wall
                << " x real time\n"
                << std::flush;
    }
  }
}

// The files written at the end (the top view, the summary), opened before
// the herd steps: a path that cannot be written is found before a long run.
struct EndFiles {
  OutputFile svg;
  OutputFile summary;
};

void open_end_files(const HerdArgs& a, EndFiles& files) {
  const auto open = [](const std::string& path, OutputFile& file, const char* option) {
    if (path.empty() || file.open(path)) return;
    throw cannot_write(option, path, file.error);
  };
  open(a.svg, files.svg, "--svg");
  open(a.summary_json, files.summary, "--summary-json");
}

// The CSV closed, the top view and the summary written.
void write_outputs(const HerdArgs& a, std::ofstream& csv, EndFiles& files,
                   const herd::TrailRecorder& trails, const herd::Herd& herd,
                   const herd::HerdMetrics& metrics, double wall_s) {
  if (csv.is_open()) {
    errno = 0;  // what the flush at close sets, if it fails
    csv.close();
    if (!csv) throw cannot_write("--out", a.out, errno);
    std::cout << "wrote " << a.out << '\n';
  }
  const auto write = [](const std::string& path, OutputFile& file, const std::string& text,
                        const char* option) {
    if (!file.is_open()) return;
    if (!file.write(text)) throw cannot_write(option, path, file.error);
    std::cout << "wrote " << path << '\n';
  };
  write(a.svg, files.svg, trails.svg(herd), "--svg");
  write(a.summary_json, files.summary, to_json(metrics, wall_s).dump(2) + '\n', "--summary-json");
}

int run_herd(const HerdArgs& a) {
  herd::HerdScene scene = herd::load_herd_scene(a.scene);
  if (a.duration) scene.duration_s = *a.duration;
  const DashboardAddress address = check_dashboard_address(a.dashboard, a.dashboard_remote);
  if (!address.ok) return kExitUsage;
  const auto& dashboard_at = address.at;
  herd::Herd herd(std::move(scene), gait_of_robot, a.seed);
  for (const std::string& w : herd.warnings()) std::cerr << w << '\n';
  // After the scene's gaits and calibrations load (a bad one leaves the last
  // run's files as they were), before the herd steps.
  EndFiles end_files;
  open_end_files(a, end_files);
  const herd::HerdScene& s = herd.scene();
  std::unique_ptr<HerdDashboardServer> dashboard;
  if (dashboard_at) dashboard = serve_dashboard(a, *dashboard_at, herd);
  if (!a.quiet) {
    std::cout << "herd " << (s.name.empty() ? s.file : s.name) << ": " << herd.agents().size()
              << " figures in " << s.groups.size() << " groups, " << s.duration_s << " s at "
              << s.step_s << " s steps, seed " << s.seed << '\n'
              << std::flush;
  }
  std::ofstream csv;
  if (!a.out.empty()) {
    errno = 0;
    csv.open(a.out);
    if (!csv) throw cannot_write("--out", a.out, errno);
    herd::write_csv_header(csv);
  }
  herd::TrailRecorder trails;
  const auto start = std::chrono::steady_clock::now();
  const auto output = [&] {
    herd.record_metrics();
    if (csv.is_open()) herd::write_csv_rows(csv, herd);
    if (!a.svg.empty()) trails.sample(herd);
  };
  output();
  step_herd(a, herd, dashboard.get(), output, start);
  if (dashboard) {
    dashboard->publish(herd);
    dashboard->stop();
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const herd::HerdMetrics metrics = herd.metrics();
  std::cout << herd::format_metrics(metrics);
  // A stop from the dashboard (or a stop signal) ends the herd early.
  const bool stopped = dashboard && dashboard->stop_requested();
  const bool signalled = dashboard && herd_signal_controls.stop.load();
  const double ran_s = stopped || signalled ? herd.time() : s.duration_s;
  std::cout << "ran " << ran_s << " s in " << wall_s << " s (" << ran_s / wall_s << " x real time)"
            << (stopped     ? ", stopped from the dashboard"
                : signalled ? ", stopped by a signal"
                            : "")
            << '\n';
  write_outputs(a, csv, end_files, trails, herd, metrics, wall_s);
  return 0;
}

}  // namespace

void add_herd_command(CLI::App& app) {
  auto args = std::make_shared<HerdArgs>();
  auto* cmd = app.add_subcommand("herd", "Run a herd of walking figures offline (flocks, crowds)");
  cmd->add_option("SCENE", args->scene, "scene file (YAML, docs/herd.md)")->required();
  cmd->add_option("--duration", args->duration, "seconds to simulate (default: the scene's)")
      ->check(FiniteRange(0.001, 1e6));
  cmd->add_option("--seed", args->seed, "random seed (overrides the scene's)")->check(kSeed);
  cmd->add_option("--out", args->out, "CSV of every agent at every output step")
      ->check(kOutputFile);
  cmd->add_option("--svg", args->svg, "top view with the trails (SVG)")->check(kOutputFile);
  cmd->add_option("--summary-json", args->summary_json, "write the metrics as JSON")
      ->check(kOutputFile);
  cmd->add_flag("--quiet", args->quiet, "no progress lines");
  cmd->add_option("--dashboard", args->dashboard,
                  "serve a live top view at HOST:PORT (port 0: a free one); the herd then walks "
                  "at real time");
  cmd->add_flag("--dashboard-remote", args->dashboard_remote,
                "allow a --dashboard host that is not loopback");
  cmd->add_option("--dashboard-speed", args->dashboard_speed,
                  "with --dashboard: the pace, in multiples of real time")
      ->check(FiniteRange(0.01, 1000.0));
  cmd->add_option("--dashboard-rate", args->dashboard_rate,
                  "with --dashboard: states streamed per second")
      ->check(FiniteRange(0.5, 200.0));
  cmd->add_option("--dashboard-www", args->dashboard_www, "folder of the dashboard's page");
  set_subcommand_body(cmd, [args] { return run_herd(*args); });
}

}  // namespace animrt::cli
