#pragma once
// Genotype -> phenotype: the GE mapping. Starting from the start rule, the
// leftmost non-terminal is expanded with production (codon mod number of
// productions); rules with a single production take no codon. When the
// genome runs out it is read again from the start (wrapping), at most
// max_wraps times; a derivation that still has non-terminals then is invalid.
//
// Structured mapping (a run file's `search: mapping: structured`) is for
// grammars whose start rule has one production, like the horse grammars'
// twelve curves: the genome is cut into equal segments, one per non-terminal
// of that production whose derivation makes choices, and each is expanded
// from its own segment, wrapping within it. A change in one curve's
// derivation then no longer shifts the codons every later curve reads (GE's
// ripple effect).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animrt/learn/evolve/grammar.hpp"

namespace animrt::evolve {

using Genome = std::vector<std::uint32_t>;

// For an invalid result, the counts say how far the mapping got.
struct MapResult {
  bool valid = false;
  std::string phenotype;  // complete only when valid
  int codons_used = 0;    // codons read, counting re-reads after wrapping
  int wraps = 0;          // times the genome (structured: any one segment) was wrapped
  int depth = 0;          // depth of the derivation tree (root = 1)
};

struct MapLimits {
  int max_wraps = 3;
  // Guards against derivations that explode even within the wraps.
  std::size_t max_phenotype_chars = 1 << 20;
};

MapResult map_genome(const Grammar& grammar, std::span<const std::uint32_t> genome,
                     const MapLimits& limits = {});

// The symbols of the start rule's production that get a segment of a
// structured genome (indices into the production, in order): its
// non-terminals whose derivations make choices. Empty when the start rule
// has several productions.
std::vector<std::size_t> structured_segment_symbols(const Grammar& grammar);
int structured_segments(const Grammar& grammar);

// Invalid when the grammar has no segments or the genome does not split
// into them evenly.
MapResult map_structured(const Grammar& grammar, std::span<const std::uint32_t> genome,
                         const MapLimits& limits = {});

}  // namespace animrt::evolve
