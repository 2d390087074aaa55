#pragma once
// Pareto ranking for the multi-objective search (NSGA-II, Deb et al. 2002):
// every objective is minimised. Fronts come from the fast non-dominated
// sort; within a front, the crowding distance prefers members far from
// their neighbours, so a front stays spread out.

#include <span>
#include <vector>

namespace animrt::evolve {

using Objectives = std::vector<double>;

// a dominates b: no worse in every objective and better in at least one.
bool dominates(std::span<const double> a, std::span<const double> b);

// Indices of points by front: front 0 is dominated by none, front 1 only by
// front 0, and so on. Each front lists its indices in increasing order.
std::vector<std::vector<int>> non_dominated_fronts(const std::vector<Objectives>& points);

// Crowding distance of each member of `front` (same order): infinite at the
// extremes of every objective, else the sum over objectives of the gap
// between its two neighbours divided by the objective's span on the front.
std::vector<double> crowding_distance(const std::vector<Objectives>& points,
                                      std::span<const int> front);

}  // namespace animrt::evolve
