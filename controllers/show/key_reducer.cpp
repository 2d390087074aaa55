#include "animrt/controllers/show/key_reducer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace animrt::show {

std::vector<std::size_t> reduce_keys(std::span<const double> times, std::span<const double> values,
                                     double tolerance) {
  if (times.size() != values.size()) {
    throw std::invalid_argument("reduce_keys: as many times as values are needed");
  }
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    throw std::invalid_argument("reduce_keys: the tolerance must be finite and >= 0");
  }
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i]) || !std::isfinite(values[i])) {
      throw std::invalid_argument("reduce_keys: times and values must be finite");
    }
    if (i > 0 && !(times[i] > times[i - 1])) {
      throw std::invalid_argument("reduce_keys: times must increase strictly");
    }
  }
  const std::size_t n = times.size();
  if (n <= 2) {
    std::vector<std::size_t> all(n);
    for (std::size_t i = 0; i < n; ++i) all[i] = i;
    return all;
  }
  std::vector<bool> keep(n, false);
  keep.front() = keep.back() = true;
  // An explicit stack: a recording of minutes has tens of thousands of samples.
  std::vector<std::pair<std::size_t, std::size_t>> spans{{0, n - 1}};
  while (!spans.empty()) {
    const auto [a, b] = spans.back();
    spans.pop_back();
    if (b <= a + 1) continue;
    const double slope = (values[b] - values[a]) / (times[b] - times[a]);
    double worst = -1.0;
    std::size_t worst_at = a;
    for (std::size_t i = a + 1; i < b; ++i) {
      const double error = std::abs(values[i] - (values[a] + slope * (times[i] - times[a])));
      if (error > worst) {
        worst = error;
        worst_at = i;
      }
    }
    if (worst > tolerance) {
      keep[worst_at] = true;
      spans.emplace_back(a, worst_at);
      spans.emplace_back(worst_at, b);
    }
  }
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) kept.push_back(i);
  }
  return kept;
}

}  // namespace animrt::show
