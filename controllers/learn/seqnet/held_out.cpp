#include "animrt/learn/seqnet/held_out.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "animrt/core/error.hpp"

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

void check_clip_names(const std::vector<std::string>& wanted, const std::vector<std::string>& have,
                      const std::string& file) {
  for (const std::string& w : wanted) {
    if (std::find(have.begin(), have.end(), w) != have.end()) continue;
    std::string known;
    for (const std::string& h : have) known += (known.empty() ? "" : ", ") + h;
    throw InputError(Location{file, 0, 0}, "--held-out-clip",
                     "no clip named '" + w + "' (the clips: " + known + ")");
  }
}

std::vector<Clip> named_clips(const std::vector<Clip>& clips, int frames,
                              const std::vector<std::string>& names, const std::string& file) {
  std::vector<Clip> all = clips;
  if (all.empty()) all.push_back(Clip{"all", 0, frames, 0.0});
  std::vector<std::string> have;
  for (const Clip& c : all) have.push_back(c.name);
  check_clip_names(names, have, file);
  std::vector<Clip> out;
  for (const Clip& c : all) {
    if (std::find(names.begin(), names.end(), c.name) != names.end()) out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const Clip& x, const Clip& y) { return x.first < y.first; });
  return out;
}

std::string compared_with(double error, double reference) {
  const double change = reference > 0 ? error / reference - 1.0 : 0.0;
  char text[48];
  std::snprintf(text, sizeof text, "%.0f %% %s", 100.0 * std::abs(change),
                change < 0 ? "better" : "worse");
  return text;
}

}  // namespace animrt::seqnet
