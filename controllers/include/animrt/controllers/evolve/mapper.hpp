#pragma once
// Genotype -> phenotype: the GE mapping. Starting from the start rule, the
// leftmost non-terminal is expanded with production (codon mod number of
// productions); rules with a single production take no codon. When the
// genome runs out it is read again from the start (wrapping), at most
// max_wraps times; a derivation that still has non-terminals then is invalid.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animrt/controllers/evolve/grammar.hpp"

namespace animrt::evolve {

using Genome = std::vector<std::uint32_t>;

struct MapResult {
  bool valid = false;
  std::string phenotype;  // complete only when valid
  int codons_used = 0;    // codons read, counting re-reads after wrapping
  int wraps = 0;          // times the genome was wrapped
  int depth = 0;          // depth of the derivation tree (root = 1)
};

struct MapLimits {
  int max_wraps = 3;
  // Guards against derivations that explode even within the wraps.
  std::size_t max_phenotype_chars = 1 << 20;
};

MapResult map_genome(const Grammar& grammar, std::span<const std::uint32_t> genome,
                     const MapLimits& limits = {});

}  // namespace animrt::evolve
