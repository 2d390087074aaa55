#include "animrt/learn/seqnet/held_out.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace animrt::seqnet {

std::pair<int, int> held_out_block(int n, double fraction, std::uint64_t seed, int dataset) {
  const int count = std::clamp(static_cast<int>(std::lround(fraction * n)), 0, n);
  if (count == 0) return {0, 0};
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(dataset) + 1);
  const int first = std::uniform_int_distribution<int>(0, n - count)(rng);
  return {first, count};
}

std::vector<Clip> held_out_pieces(int n, const std::vector<Clip>& clips, double fraction,
                                  std::uint64_t seed, int dataset) {
  const auto [first, count] = held_out_block(n, fraction, seed, dataset);
  std::vector<Clip> all = clips;
  if (all.empty()) all.push_back(Clip{"all", 0, n, 0.0});
  std::vector<Clip> out;
  for (const Clip& c : all) {
    const int a = std::max(c.first, first);
    const int b = std::min(c.first + c.count, first + count);
    if (a < b) out.push_back(Clip{c.name, a, b - a, c.fps});
  }
  std::sort(out.begin(), out.end(), [](const Clip& x, const Clip& y) { return x.first < y.first; });
  return out;
}

}  // namespace animrt::seqnet
