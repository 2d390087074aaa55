// The evolve subcommand: load the run file, grammar, seed gait and model,
// run the search (threads, optionally MPI ranks), write gait, CSV and plot.

#include "evolve_command.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/evolve/mpi_evaluator.hpp"
#include "animrt/learn/evolve/report.hpp"
#include "animrt/learn/evolve/search.hpp"
#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/evolve_dashboard.hpp"
#include "animrt/sim/mujoco/mujoco_figure.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "dashboard_address.hpp"
#include "data_dir.hpp"
#include "evolve_pareto.hpp"
#include "option_checks.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"
#include "walk_as_robot.hpp"

namespace animrt::cli {
namespace {

struct EvolveArgs {
  std::string run_file;
  std::string out;
  std::string robot;  // overrides the run file's robot:
  std::optional<int> threads;
  std::optional<std::uint64_t> seed;
  std::optional<int> population;
  std::optional<int> generations;
  std::string csv;
  std::string plot;
  bool mpi = false;
  bool quiet = false;
  bool pareto = false;
  std::string dashboard;  // HOST:PORT, "" for none
  bool dashboard_remote = false;
  double dashboard_rate = 30.0;
  std::string dashboard_www = animrt::cli::dashboard_www_dir();
  bool keep_serving = false;
};

std::string with_extension(const std::string& path, const std::string& ext) {
  return std::filesystem::path(path).replace_extension(ext).string();
}

RunControls evolve_signal_controls;  // a search takes only its stop

// The search has ended and its page shows the end: with --keep-serving the
// page stays until a stop signal; without, the user is told it closes (a
// short search ends before anyone opens the page).
void end_dashboard(EvolveDashboardServer* dashboard, bool keep_serving) {
  if (!dashboard) return;
  if (!keep_serving) {
    std::cout << "the search has ended: its dashboard page closes now (--keep-serving keeps it "
                 "until Ctrl-C)\n"
              << std::flush;
    return;
  }
  if (evolve_signal_controls.stop.load()) return;  // stopped by a signal: no more serving
  std::cout << "the search has ended: its dashboard page stays at " << dashboard->url()
            << " until Ctrl-C\n"
            << std::flush;
  while (!evolve_signal_controls.stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  dashboard->stop();
}

// The run file with the command line's overrides.
evolve::RunConfig load_config(const EvolveArgs& a) {
  evolve::RunConfig config = evolve::load_run_config(a.run_file);
  if (a.seed) config.search.seed = *a.seed;
  if (a.population) config.search.population = *a.population;
  // --generations counts the initial one; the run file counts those after it.
  if (a.generations) config.search.generations = *a.generations - 1;
  if (a.threads) config.threads = *a.threads;
  if (!a.robot.empty()) config.robot = a.robot;
  if (config.search.elites >= config.search.population) {
    config.search.elites = std::max(0, config.search.population - 1);
  }
  return config;
}

// The seed gait must drive joints the model has (errors name the gait file).
void check_seed_drives_model(const GaitFile& seed, const sim::MujocoGaitSimulatorFactory& factory) {
  std::vector<JointSpec> specs;
  for (const auto& j : factory.model().actuated_joints) {
    JointSpec s;
    s.name = j;
    s.limits = {-kPi, kPi, 100.0, 10000.0};
    specs.push_back(s);
  }
  (void)make_gait_source(seed, specs);
}

// The dashboard (rank 0's), which poses `figure` from the model; its line
// comes first.
std::unique_ptr<EvolveDashboardServer> serve_dashboard(
    const EvolveArgs& a, const std::pair<std::string, int>& dashboard_at,
    const evolve::RunConfig& config, const evolve::ModelInfo& info, int workers,
    std::unique_ptr<sim::MujocoFigure>& figure) {
  figure =
      std::make_unique<sim::MujocoFigure>(config.model, info.joints, Location{config.file, 0, 0});
  EvolveDashboardSetup setup;
  setup.host = dashboard_at.first;
  setup.port = dashboard_at.second;
  setup.remote = a.dashboard_remote;
  setup.rate_hz = a.dashboard_rate;
  setup.www_dir = a.dashboard_www;
  setup.name = config.name;
  setup.run_file = config.file;
  setup.grammar = config.grammar;
  setup.model_file = config.model;
  setup.population = config.search.population;
  setup.generations = config.search.generations;
  setup.seed = config.search.seed;
  setup.workers = workers;
  setup.joints = info.joints;
  setup.figure = figure.get();
  auto dashboard = std::make_unique<EvolveDashboardServer>(setup);
  std::cout << "dashboard: " << dashboard->url() << '\n' << std::flush;
  return dashboard;
}

void print_header(const evolve::RunConfig& config, const evolve::ModelInfo& info, int workers,
                  const evolve::MpiSession* session) {
  std::cout << "evolve " << config.name << ": grammar " << config.grammar
            << (config.search.mapping == evolve::Mapping::structured ? " (structured mapping)" : "")
            << ", model " << config.model << " (" << info.joints.size() << " actuators, "
            << info.mass_kg << " kg), population " << config.search.population << ", "
            << config.search.generations + 1 << " generations, seed " << config.search.seed << ", "
            << workers << " worker" << (workers == 1 ? "" : "s")
            << (session ? " over " + std::to_string(session->size()) + " MPI ranks" : "") << '\n';
  if (!config.robot.empty()) std::cout << describe_walk_as_robot(config.robot, config.walk) << '\n';
  std::cout << std::flush;
}

// The history's CSV and plot: as given, else beside --out.
std::string history_csv(const EvolveArgs& a) {
  return a.csv.empty() ? with_extension(a.out, ".csv") : a.csv;
}
std::string history_plot(const EvolveArgs& a) {
  return a.plot.empty() ? with_extension(a.out, ".svg") : a.plot;
}

// The history (CSV and plot) and the best gait written, the best reported.
int write_results(const EvolveArgs& a, const evolve::RunConfig& config,
                  const evolve::SearchResult& result, EvolveDashboardServer* dashboard) {
  const std::string csv = history_csv(a);
  const std::string plot = history_plot(a);
  evolve::write_history_csv(result.history, csv);
  evolve::write_history_svg(result.history, config.name, plot);
  const auto& best = result.best;
  if (!best.valid) {
    if (dashboard) dashboard->finish(result.stopped, a.keep_serving);
    std::cerr << "error: no valid individual in the last generation; no gait written\n";
    end_dashboard(dashboard, a.keep_serving);
    return 4;
  }
  write_gait_file(best.gait, a.out);
  // The page shows the end once every file is written.
  if (dashboard) dashboard->finish(result.stopped, a.keep_serving);
  const auto& m = best.measures;
  std::cout << "best fitness " << best.fitness << (m.fell ? " (falls)" : "") << ": speed "
            << m.speed << " m/s, stride " << m.stride_length << " m, duty factor " << m.duty_factor
            << ", energy " << m.energy_per_cycle << " J/cycle\n"
            << "evaluations " << result.evaluations << " (and " << result.reused
            << " repeated gaits not walked again), invalid " << result.invalid << '\n'
            << "wrote " << a.out << ", " << csv << ", " << plot << '\n';
  end_dashboard(dashboard, a.keep_serving);
  return 0;
}

// Progress lines and the dashboard per generation. With `stoppable`, a
// stop from the dashboard (or a stop signal, while it serves: a second one
// ends the process at once) ends the search after the generation it arrived
// in, files written; under MPI rank 0's answer is every rank's.
evolve::SearchHooks search_hooks(const EvolveArgs& a, bool lead, int generations,
                                 EvolveDashboardServer* dashboard, evolve::MpiSession* session,
                                 bool stoppable) {
  evolve::SearchHooks hooks;
  hooks.generation = [&a, lead, generations, dashboard](const evolve::GenerationStats& s,
                                                        const evolve::Individual& best) {
    if (lead && !a.quiet)
      std::cout << evolve::format_progress(s, generations) << '\n' << std::flush;
    if (dashboard) dashboard->publish(s, best);
  };
  if (stoppable) {
    install_stop_signals(evolve_signal_controls, SecondSignal::end_process);
    hooks.stop = [dashboard, session] {
      const bool stop =
          (dashboard && dashboard->stop_requested()) || evolve_signal_controls.stop.load();
      return session ? session->broadcast(stop) : stop;
    };
  }
  return hooks;
}

int run_evolve(const EvolveArgs& a) {
  if (a.pareto && !a.dashboard.empty()) {
    std::cerr << "--dashboard shows the single-objective search; it does not go with --pareto\n";
    return kExitUsage;
  }
  if (!output_option_ok("--out", a.out, a.pareto ? kOutputFolder : kOutputFile)) return kExitUsage;
  // The files written beside the gait too, before the search (a folder in
  // the way lost the search's gait after it).
  if (!a.pareto &&
      (!output_option_ok(a.csv.empty() ? "--out's .csv" : "--csv", history_csv(a), kOutputFile) ||
       !output_option_ok(a.plot.empty() ? "--out's .svg" : "--plot", history_plot(a),
                         kOutputFile))) {
    return kExitUsage;
  }
  // The dashboard's address is a usage error before any file is read.
  const DashboardAddress address = check_dashboard_address(a.dashboard, a.dashboard_remote);
  if (!address.ok) return kExitUsage;
  const auto& dashboard_at = address.at;
  evolve::RunConfig config = load_config(a);
  evolve::Grammar grammar = evolve::Grammar::load_file(config.grammar);
  GaitFile seed = load_gait_file(config.seed_gait);
  sim::MujocoGaitSimulatorFactory factory(config.model);
  check_seed_drives_model(seed, factory);
  evolve::ModelInfo info{factory.model().actuated_joints, factory.model().hip_height_m,
                         factory.model().mass_kg};
  if (!config.robot.empty()) walk_as_robot(config.robot, info, config.walk);

  std::unique_ptr<evolve::MpiSession> session;
  if (a.mpi) session = std::make_unique<evolve::MpiSession>(nullptr, nullptr);
  const bool lead = !session || session->rank() == 0;
  const int threads = config.threads > 0
                          ? config.threads
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  evolve::ThreadEvaluator local(factory, threads);
  std::unique_ptr<evolve::MpiEvaluator> distributed;
  if (session) distributed = std::make_unique<evolve::MpiEvaluator>(*session, local);
  evolve::Evaluator& evaluator =
      distributed ? static_cast<evolve::Evaluator&>(*distributed) : local;

  const int workers = evaluator.workers();
  std::unique_ptr<sim::MujocoFigure> figure;
  std::unique_ptr<EvolveDashboardServer> dashboard;
  if (dashboard_at && lead) {
    dashboard = serve_dashboard(a, *dashboard_at, config, info, workers, figure);
  }
  if (lead && !a.quiet) print_header(config, info, workers, session.get());
  if (a.pareto) {
    return run_pareto_search(config, std::move(grammar), seed, info, evaluator,
                             {a.out, lead, a.quiet});
  }
  const int generations = config.search.generations;
  evolve::Search search(config, std::move(grammar), seed, info, evaluator);
  const evolve::SearchResult result = search.run(
      search_hooks(a, lead, generations, dashboard.get(), session.get(), dashboard_at.has_value()));
  if (!lead) return 0;
  if (result.stopped) {
    std::cout << (evolve_signal_controls.stop.load() ? "stopped by a signal"
                                                     : "stopped from the dashboard")
              << " after generation " << result.history.back().generation << " of " << generations
              << '\n';
  }
  return write_results(a, config, result, dashboard.get());
}

}  // namespace

void add_evolve_command(CLI::App& app) {
  auto args = std::make_shared<EvolveArgs>();
  auto* cmd = app.add_subcommand("evolve",
                                 "Evolve a gait with Grammatical Evolution against a MuJoCo model");
  cmd->add_option("RUN", args->run_file, "evolve run file (YAML)")->required();
  cmd->add_option("--out", args->out,
                  "gait file to write (best of the last generation); with --pareto, a folder")
      ->required();
  cmd->add_option("--robot", args->robot,
                  "score every gait as this robot file's figure plays it: its joint limits at "
                  "its loop rate, the reflex reading the attitude as its IMU reports it "
                  "(overrides the run file's robot:)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--threads", args->threads, "evaluation threads (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--seed", args->seed, "random seed (overrides the run file)")->check(kSeed);
  cmd->add_option("--population", args->population, "population size")
      ->check(CLI::Range(2, 1000000));
  cmd->add_option("--generations", args->generations,
                  "generations to run, the initial one included (1: the initial population "
                  "only; the run file's search.generations counts those after it)")
      ->check(CLI::Range(1, 1000001));
  cmd->add_option("--csv", args->csv, "per-generation statistics (default: OUT with .csv)")
      ->check(kOutputFile);
  cmd->add_option("--plot", args->plot, "best/average fitness plot (default: OUT with .svg)")
      ->check(kOutputFile);
  cmd->add_flag("--mpi", args->mpi, "spread evaluations over MPI ranks (launch with mpirun)");
  cmd->add_flag("--quiet", args->quiet, "no progress lines");
  cmd->add_flag("--pareto", args->pareto,
                "multi-objective search (speed error, energy, tilt): write the Pareto front's "
                "gaits, front.csv, front.svg and history.csv into the --out folder");
  cmd->add_option("--dashboard", args->dashboard,
                  "serve a live page at HOST:PORT (port 0: a free one; loopback only unless "
                  "--dashboard-remote): fitness curves, the best gait so far on the model, stop");
  cmd->add_flag("--dashboard-remote", args->dashboard_remote,
                "let the dashboard listen on an address other machines can reach");
  cmd->add_option("--dashboard-rate", args->dashboard_rate, "dashboard stream rate in Hz")
      ->check(FiniteRange(0.5, 200.0));
  cmd->add_option("--dashboard-www", args->dashboard_www, "folder of the dashboard's page")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--keep-serving", args->keep_serving,
                "with --dashboard: keep serving the page after the search ends, until Ctrl-C");
  set_subcommand_body(cmd, [args] { return run_evolve(*args); });
}

}  // namespace animrt::cli
