// BNF grammars: a grammar that loads is also mapped from a genome taken from
// the input, within the mapper's limits.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "animrt/learn/evolve/grammar.hpp"
#include "animrt/learn/evolve/mapper.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt::evolve;
  try {
    const Grammar g = Grammar::parse(animrt::fuzz::as_text(data, size), "fuzz.bnf");
    std::vector<std::uint32_t> genome(16, 0);
    std::memcpy(genome.data(), data, std::min(size, genome.size() * 4));
    MapLimits limits;
    limits.max_phenotype_chars = 1 << 16;
    (void)map_genome(g, genome, limits);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
