// Initialisation, selection, crossover and mutation (see operators.hpp).

#include "animrt/learn/evolve/operators.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace animrt::evolve {
namespace {

std::uint32_t codon_for(std::size_t choice, std::size_t productions, std::uint32_t codon_size,
                        Rng& rng) {
  const std::uint64_t blocks = std::max<std::uint64_t>(1, codon_size / productions);
  return static_cast<std::uint32_t>(choice + productions * rng.below(blocks));
}

void derive(const Grammar& g, int rule_index, int depth, int max_depth, bool grow,
            const InitSettings& s, Rng& rng, Genome& out) {
  const Rule& rule = g.rules()[static_cast<std::size_t>(rule_index)];
  const int room = max_depth - depth + 1;  // depth this subtree may still use
  std::vector<std::size_t> fit;
  std::vector<std::size_t> fit_recursive;
  for (std::size_t i = 0; i < rule.productions.size(); ++i) {
    const Production& p = rule.productions[i];
    if (p.min_depth <= room) {
      fit.push_back(i);
      if (p.recursive) fit_recursive.push_back(i);
    }
  }
  if (fit.empty()) {  // only when max_depth is below the grammar's minimum
    std::size_t best = 0;
    for (std::size_t i = 1; i < rule.productions.size(); ++i) {
      if (rule.productions[i].min_depth < rule.productions[best].min_depth) best = i;
    }
    fit.push_back(best);
  }
  const auto& pool = (!grow && !fit_recursive.empty()) ? fit_recursive : fit;
  const std::size_t choice = pool[static_cast<std::size_t>(rng.index(pool.size()))];
  if (rule.productions.size() > 1) {
    out.push_back(codon_for(choice, rule.productions.size(), s.codon_size, rng));
  }
  for (const auto& sym : rule.productions[choice].symbols) {
    if (!sym.terminal) derive(g, sym.rule, depth + 1, max_depth, grow, s, rng, out);
  }
}

// The depth of individual i of a ramp from the start rule's minimum depth to
// max_depth (or to that minimum, when it is deeper).
int ramp_depth(const Grammar& grammar, const InitSettings& settings, int i) {
  const int lo = grammar.start().min_depth;
  const int hi = std::max(lo, settings.max_depth);
  return lo + i % (hi - lo + 1);
}

}  // namespace

Genome derive_genome(const Grammar& grammar, int depth, bool grow, const InitSettings& settings,
                     Rng& rng) {
  Genome g;
  derive(grammar, 0, 1, depth, grow, settings, rng, g);
  const auto tail = static_cast<std::size_t>(
      std::ceil(settings.tail_ratio * static_cast<double>(std::max<std::size_t>(g.size(), 1))));
  for (std::size_t i = 0; i < tail; ++i) {
    g.push_back(static_cast<std::uint32_t>(rng.below(settings.codon_size)));
  }
  return g;
}

std::vector<Genome> ramped_full_grow(const Grammar& grammar, int count,
                                     const InitSettings& settings, Rng& rng) {
  std::vector<Genome> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const int depth = ramp_depth(grammar, settings, i);
    const bool grow = rng.chance(settings.grow_probability);
    out.push_back(derive_genome(grammar, depth, grow, settings, rng));
  }
  return out;
}

std::vector<Genome> ramped_structured(const Grammar& grammar, int count,
                                      const InitSettings& settings, Rng& rng) {
  std::vector<int> segment_rules;
  for (const std::size_t i : structured_segment_symbols(grammar)) {
    segment_rules.push_back(grammar.start().productions.front().symbols[i].rule);
  }
  std::vector<std::vector<Genome>> derived(static_cast<std::size_t>(count));
  std::size_t longest = 1;
  for (int i = 0; i < count; ++i) {
    const int depth = ramp_depth(grammar, settings, i);
    const bool grow = rng.chance(settings.grow_probability);
    for (const int rule : segment_rules) {
      Genome segment;
      derive(grammar, rule, 2, depth, grow, settings, rng, segment);
      longest = std::max(longest, segment.size());
      derived[static_cast<std::size_t>(i)].push_back(std::move(segment));
    }
  }
  // Every segment of every genome gets the same length, so that fixed-point
  // crossover and mutation keep segments where the mapping looks for them.
  const auto length = static_cast<std::size_t>(
      std::ceil((1.0 + settings.tail_ratio) * static_cast<double>(longest)));
  std::vector<Genome> out;
  out.reserve(derived.size());
  for (auto& segments : derived) {
    Genome g;
    for (auto& segment : segments) {
      while (segment.size() < length) {
        segment.push_back(static_cast<std::uint32_t>(rng.below(settings.codon_size)));
      }
      g.insert(g.end(), segment.begin(), segment.end());
    }
    out.push_back(std::move(g));
  }
  return out;
}

int tournament(std::span<const double> fitness, int size, Rng& rng) {
  int best = rng.index(fitness.size());
  for (int k = 1; k < size; ++k) {
    const int c = rng.index(fitness.size());
    const auto ci = static_cast<std::size_t>(c);
    const auto bi = static_cast<std::size_t>(best);
    if (fitness[ci] < fitness[bi] || (fitness[ci] == fitness[bi] && c < best)) best = c;
  }
  return best;
}

void fixed_point_crossover(Genome& a, Genome& b, double probability, Rng& rng) {
  if (!rng.chance(probability)) return;
  const std::size_t shorter = std::min(a.size(), b.size());
  if (shorter < 2) return;
  const std::size_t point = 1 + static_cast<std::size_t>(rng.below(shorter - 1));
  Genome tail_a(a.begin() + static_cast<std::ptrdiff_t>(point), a.end());
  a.resize(point);
  a.insert(a.end(), b.begin() + static_cast<std::ptrdiff_t>(point), b.end());
  b.resize(point);
  b.insert(b.end(), tail_a.begin(), tail_a.end());
}

void int_flip_mutation(Genome& g, double probability, std::uint32_t codon_size, Rng& rng) {
  for (auto& c : g) {
    if (rng.chance(probability)) c = static_cast<std::uint32_t>(rng.below(codon_size));
  }
}

}  // namespace animrt::evolve
