// The GE genotype-to-phenotype mapping (see mapper.hpp).

#include "animrt/learn/evolve/mapper.hpp"

#include <algorithm>

namespace animrt::evolve {
namespace {

// Expands `root` leftmost-first from `codons` (wrapping within them), appending
// its terminal text to out.phenotype. `root_depth` is the depth of root's node.
// Returns false when the codons ran out of wraps or the text grew too long.
bool expand(const Grammar& grammar, const Symbol& root, int root_depth,
            std::span<const std::uint32_t> codons, const MapLimits& limits, MapResult& out) {
  struct Pending {
    const Symbol* symbol;
    int depth;
  };
  std::vector<Pending> stack{{&root, root_depth}};
  const std::size_t max_reads = codons.size() * static_cast<std::size_t>(limits.max_wraps + 1);
  std::size_t reads = 0;
  bool finished = true;
  while (!stack.empty()) {
    const Pending top = stack.back();
    stack.pop_back();
    if (top.symbol->terminal) {
      out.phenotype += top.symbol->text;
      if (out.phenotype.size() > limits.max_phenotype_chars) {
        finished = false;
        break;
      }
      continue;
    }
    out.depth = std::max(out.depth, top.depth);  // depth counts non-terminal nodes
    const Rule& rule = grammar.rules()[static_cast<std::size_t>(top.symbol->rule)];
    std::size_t choice = 0;
    if (rule.productions.size() > 1) {
      if (reads >= max_reads) {
        finished = false;
        break;
      }
      choice = codons[reads % codons.size()] % rule.productions.size();
      ++reads;
    }
    const auto& symbols = rule.productions[choice].symbols;
    for (auto it = symbols.rbegin(); it != symbols.rend(); ++it) {
      stack.push_back({&*it, top.depth + 1});
    }
  }
  out.codons_used += static_cast<int>(reads);
  if (!codons.empty() && reads > 0) {
    out.wraps = std::max(out.wraps, static_cast<int>((reads - 1) / codons.size()));
  }
  return finished;
}

MapResult invalid(MapResult out) {
  out.valid = false;
  out.phenotype.clear();
  return out;
}

}  // namespace

MapResult map_genome(const Grammar& grammar, std::span<const std::uint32_t> genome,
                     const MapLimits& limits) {
  MapResult out;
  const Symbol start{false, grammar.start().name, 0};
  if (!expand(grammar, start, 1, genome, limits, out)) return invalid(std::move(out));
  out.valid = true;
  return out;
}

std::vector<std::size_t> structured_segment_symbols(const Grammar& grammar) {
  const Rule& start = grammar.start();
  if (start.productions.size() != 1) return {};
  // Rules whose derivation never makes a choice (the horse grammars'
  // <newline>) read no codons and get no segment.
  const auto& rules = grammar.rules();
  std::vector<int> chooses(rules.size(), -1);  // -1 unknown, 0 no, 1 yes
  const auto makes_choices = [&](int rule, auto& self) -> bool {
    auto& known = chooses[static_cast<std::size_t>(rule)];
    if (known >= 0) return known == 1;
    known = 0;  // a cycle back here adds no choice of its own
    const Rule& r = rules[static_cast<std::size_t>(rule)];
    bool yes = r.productions.size() > 1;
    for (const auto& p : r.productions) {
      for (const auto& sym : p.symbols) {
        if (!yes && !sym.terminal) yes = self(sym.rule, self);
      }
    }
    known = yes ? 1 : 0;
    return yes;
  };
  std::vector<std::size_t> out;
  const auto& symbols = start.productions.front().symbols;
  for (std::size_t i = 0; i < symbols.size(); ++i) {
    if (!symbols[i].terminal && makes_choices(symbols[i].rule, makes_choices)) out.push_back(i);
  }
  return out;
}

int structured_segments(const Grammar& grammar) {
  return static_cast<int>(structured_segment_symbols(grammar).size());
}

MapResult map_structured(const Grammar& grammar, std::span<const std::uint32_t> genome,
                         const MapLimits& limits) {
  MapResult out;
  const std::vector<std::size_t> segmented = structured_segment_symbols(grammar);
  const std::size_t segments = segmented.size();
  if (segments == 0 || genome.empty() || genome.size() % segments != 0) return invalid(out);
  const std::size_t length = genome.size() / segments;
  out.depth = 1;  // the start rule's node
  const auto& symbols = grammar.start().productions.front().symbols;
  std::size_t segment = 0;
  for (std::size_t i = 0; i < symbols.size(); ++i) {
    if (symbols[i].terminal) {
      out.phenotype += symbols[i].text;
      continue;
    }
    std::span<const std::uint32_t> codons;  // none for a rule without choices
    if (segment < segments && segmented[segment] == i) {
      codons = genome.subspan(segment * length, length);
      ++segment;
    }
    if (!expand(grammar, symbols[i], 2, codons, limits, out)) return invalid(std::move(out));
  }
  out.valid = true;
  return out;
}

}  // namespace animrt::evolve
