#pragma once
// Genetic operators on integer codon genomes: ramped full/grow
// initialisation through the grammar, tournament selection, fixed-point
// one-point crossover and int-flip mutation.

#include <cstdint>
#include <span>
#include <vector>

#include "animrt/learn/evolve/grammar.hpp"
#include "animrt/learn/evolve/mapper.hpp"
#include "animrt/learn/evolve/random.hpp"

namespace animrt::evolve {

struct InitSettings {
  int max_depth = 10;                   // deepest derivation tree the ramp reaches
  double grow_probability = 0.5;        // else full
  double tail_ratio = 0.5;              // random codons appended, relative to the used length
  std::uint32_t codon_size = 1u << 16;  // codons are drawn from [0, codon_size)
};

// One genome whose derivation has depth <= `depth`: "full" keeps choosing
// recursive productions until the depth forces an exit; "grow" picks any
// production that still fits. Each choice is written as a codon that maps to
// it (choice + k * productions), then a random tail is appended.
Genome derive_genome(const Grammar& grammar, int depth, bool grow, const InitSettings& settings,
                     Rng& rng);

// `count` genomes with depths ramped from the start rule's minimum depth to
// max_depth (a grammar whose minimum exceeds max_depth ramps up to its minimum).
std::vector<Genome> ramped_full_grow(const Grammar& grammar, int count,
                                     const InitSettings& settings, Rng& rng);

// Genomes for structured mapping (mapper.hpp): the same ramp, each segment
// derived from its own non-terminal of the start rule's production, then every
// segment of every genome padded with random codons to one length,
// (1 + tail_ratio) times the longest derived segment. Equal lengths keep the
// segments aligned through fixed-point crossover, which then swaps whole
// later segments and splits at most one. Empty genomes when the start rule has
// several productions.
std::vector<Genome> ramped_structured(const Grammar& grammar, int count,
                                      const InitSettings& settings, Rng& rng);

// Index of the best (lowest fitness; earlier index on ties) of `size`
// individuals drawn uniformly with replacement.
int tournament(std::span<const double> fitness, int size, Rng& rng);

// With probability `probability`, swaps the tails of a and b after one point
// chosen in both at the same position, within the shorter genome.
void fixed_point_crossover(Genome& a, Genome& b, double probability, Rng& rng);

// Each codon is replaced by a random codon with probability `probability`.
void int_flip_mutation(Genome& g, double probability, std::uint32_t codon_size, Rng& rng);

}  // namespace animrt::evolve
