// The GE genotype-to-phenotype mapping (see mapper.hpp).

#include "animrt/controllers/evolve/mapper.hpp"

#include <algorithm>

namespace animrt::evolve {

MapResult map_genome(const Grammar& grammar, std::span<const std::uint32_t> genome,
                     const MapLimits& limits) {
  MapResult out;
  struct Pending {
    const Symbol* symbol;
    int depth;
  };
  const Symbol start{false, grammar.start().name, 0};
  std::vector<Pending> stack{{&start, 1}};
  const std::size_t max_reads = genome.size() * static_cast<std::size_t>(limits.max_wraps + 1);
  std::size_t reads = 0;
  while (!stack.empty()) {
    const Pending top = stack.back();
    stack.pop_back();
    if (top.symbol->terminal) {
      out.phenotype += top.symbol->text;
      if (out.phenotype.size() > limits.max_phenotype_chars) return {};
      continue;
    }
    out.depth = std::max(out.depth, top.depth);  // depth counts non-terminal nodes
    const Rule& rule = grammar.rules()[static_cast<std::size_t>(top.symbol->rule)];
    std::size_t choice = 0;
    if (rule.productions.size() > 1) {
      if (reads >= max_reads) {
        out.valid = false;
        out.codons_used = static_cast<int>(reads);
        out.phenotype.clear();
        return out;
      }
      choice = genome[reads % genome.size()] % rule.productions.size();
      ++reads;
    }
    const auto& symbols = rule.productions[choice].symbols;
    for (auto it = symbols.rbegin(); it != symbols.rend(); ++it) {
      stack.push_back({&*it, top.depth + 1});
    }
  }
  out.valid = true;
  out.codons_used = static_cast<int>(reads);
  out.wraps = genome.empty() || reads == 0 ? 0 : static_cast<int>((reads - 1) / genome.size());
  return out;
}

}  // namespace animrt::evolve
