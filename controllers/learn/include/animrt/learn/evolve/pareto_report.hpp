#pragma once
// Output of a Pareto run: a progress line per generation, the history as
// CSV, the front as CSV (one row per member, with the gait file it was
// written to) and as an SVG scatter of speed error against energy, each
// point coloured by its tilt.

#include <string>
#include <vector>

#include "animrt/learn/evolve/pareto_search.hpp"

namespace animrt::evolve {

// e.g. "gen 3/50  front 12  best speed err 0.081  energy 2.31  tilt 3.2 deg  fell 20  ..."
std::string format_pareto_progress(const ParetoGeneration& g, int generations);

void write_pareto_history_csv(const std::vector<ParetoGeneration>& history,
                              const std::string& path);

// gait_files[i] is where front[i]'s gait was written (a name, for the CSV).
void write_pareto_front_csv(const std::vector<ParetoMember>& front,
                            const std::vector<std::string>& gait_files, const std::string& path);

void write_pareto_front_svg(const std::vector<ParetoMember>& front, const std::string& title,
                            const std::string& path);

}  // namespace animrt::evolve
