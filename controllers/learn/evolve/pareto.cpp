// Non-dominated sorting and crowding distance (see pareto.hpp).

#include "animrt/learn/evolve/pareto.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>

namespace animrt::evolve {

bool dominates(std::span<const double> a, std::span<const double> b) {
  bool better = false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k] > b[k]) return false;
    if (a[k] < b[k]) better = true;
  }
  return better;
}

std::vector<std::vector<int>> non_dominated_fronts(const std::vector<Objectives>& points) {
  const std::size_t n = points.size();
  std::vector<std::vector<int>> dominated(n);  // whom i dominates
  std::vector<int> dominators(n, 0);           // how many dominate i
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      if (dominates(points[i], points[j])) {
        dominated[i].push_back(static_cast<int>(j));
        ++dominators[j];
      } else if (dominates(points[j], points[i])) {
        dominated[j].push_back(static_cast<int>(i));
        ++dominators[i];
      }
    }
  }
  std::vector<std::vector<int>> fronts;
  std::vector<int> current;
  for (std::size_t i = 0; i < n; ++i) {
    if (dominators[i] == 0) current.push_back(static_cast<int>(i));
  }
  while (!current.empty()) {
    std::vector<int> next;
    for (int i : current) {
      for (int j : dominated[static_cast<std::size_t>(i)]) {
        if (--dominators[static_cast<std::size_t>(j)] == 0) next.push_back(j);
      }
    }
    std::sort(next.begin(), next.end());
    fronts.push_back(std::move(current));
    current = std::move(next);
  }
  return fronts;
}

std::vector<double> crowding_distance(const std::vector<Objectives>& points,
                                      std::span<const int> front) {
  const std::size_t m = front.size();
  std::vector<double> distance(m, 0.0);
  if (m == 0) return distance;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const std::size_t objectives = points[static_cast<std::size_t>(front[0])].size();
  std::vector<std::size_t> order(m);
  for (std::size_t k = 0; k < objectives; ++k) {
    const auto value = [&](std::size_t i) { return points[static_cast<std::size_t>(front[i])][k]; };
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return value(a) < value(b); });
    distance[order.front()] = kInf;
    distance[order.back()] = kInf;
    const double span = value(order.back()) - value(order.front());
    if (!(span > 0.0) || !std::isfinite(span)) continue;  // all equal, or all unwalked
    for (std::size_t r = 1; r + 1 < m; ++r) {
      distance[order[r]] += (value(order[r + 1]) - value(order[r - 1])) / span;
    }
  }
  return distance;
}

}  // namespace animrt::evolve
