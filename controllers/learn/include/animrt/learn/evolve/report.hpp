#pragma once
// What an evolve run leaves behind besides the gait: per-generation
// statistics as CSV and a plot of best and average fitness as SVG.

#include <string>
#include <vector>

#include "animrt/learn/evolve/search.hpp"

namespace animrt::evolve {

// One progress line, e.g. "gen 3/50  best 123.4  avg 456.7 (sd 12.3)  invalid 2  fell 5  68 evals
// 212.3 evals/s".
std::string format_progress(const GenerationStats& s, int generations);

// generation,best,average,stddev,invalid,fell,evaluations,seconds,evals_per_s,best_speed,
// best_stride_length,best_duty_factor,best_energy_per_cycle. Throws std::runtime_error when
// the file cannot be written.
void write_history_csv(const std::vector<GenerationStats>& history, const std::string& path);

// Best and average fitness against generation, log-scaled fitness axis.
void write_history_svg(const std::vector<GenerationStats>& history, const std::string& title,
                       const std::string& path);

}  // namespace animrt::evolve
