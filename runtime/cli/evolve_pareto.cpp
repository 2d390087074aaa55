// `animrt evolve RUN --pareto --out DIR`: the multi-objective search, its
// front written as one playable gait file per member with a CSV and a plot.

#include "evolve_pareto.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "animrt/learn/evolve/pareto_report.hpp"
#include "animrt/learn/evolve/pareto_search.hpp"

namespace animrt::cli {

int run_pareto_search(const evolve::RunConfig& config, evolve::Grammar grammar,
                      const GaitFile& seed, const evolve::ModelInfo& info,
                      evolve::Evaluator& evaluator, const ParetoOutput& output) {
  const int generations = config.search.generations;
  evolve::ParetoSearch search(config, std::move(grammar), seed, info, evaluator);
  const evolve::ParetoResult result = search.run([&](const evolve::ParetoGeneration& g) {
    if (output.lead && !output.quiet)
      std::cout << evolve::format_pareto_progress(g, generations) << '\n' << std::flush;
  });
  if (!output.lead) return 0;

  namespace fs = std::filesystem;
  const fs::path dir(output.dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + output.dir + ": " + ec.message());
  // Gait files from an earlier run in the same folder would read as members.
  for (const auto& entry : fs::directory_iterator(dir)) {
    const auto name = entry.path().filename().string();
    if (name.rfind("gait_", 0) == 0 && entry.path().extension() == ".yaml") fs::remove(entry);
  }
  std::vector<std::string> files;
  for (std::size_t i = 0; i < result.front.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "gait_%02zu.yaml", i + 1);
    GaitFile gait = result.front[i].individual.gait;
    gait.name = config.name + "_pareto_" + std::to_string(i + 1);
    write_gait_file(gait, (dir / name).string());
    files.emplace_back(name);
  }
  evolve::write_pareto_front_csv(result.front, files, (dir / "front.csv").string());
  evolve::write_pareto_front_svg(result.front, config.name, (dir / "front.svg").string());
  evolve::write_pareto_history_csv(result.history, (dir / "history.csv").string());
  std::cout << "front: " << result.front.size() << " gaits (speed error, energy, tilt):\n";
  for (std::size_t i = 0; i < result.front.size(); ++i) {
    const auto& o = result.front[i].objectives;
    std::printf("  %s  %.3f  %.3f  %.1f deg\n", files[i].c_str(), o[0], o[1], o[2]);
  }
  std::cout << "evaluations " << result.evaluations << "\nwrote " << output.dir
            << "/{gait_NN.yaml, front.csv, front.svg, history.csv}\n";
  if (result.front.empty()) {
    std::cerr << "error: no individual of the last generation walks without falling\n";
    return 4;
  }
  return 0;
}

}  // namespace animrt::cli
