// The GE mapping (worked by hand), wrapping, invalid individuals, and the
// genetic operators.

#include "animrt/controllers/evolve/mapper.hpp"

#include <gtest/gtest.h>

#include <set>

#include "animrt/controllers/evolve/operators.hpp"
#include "animrt/controllers/gait/expression.hpp"

namespace animrt::evolve {
namespace {

// <e>  has 3 productions, <op> 2, <v> 3; <s> has one (takes no codon).
const char* kSmall =
    "<s> ::= <e>\n"
    "<e> ::= <e><op><e> | sin(<v>*2*PI*t) | <v>\n"
    "<op> ::= + | -\n"
    "<v> ::= 1 | 2 | 3\n";

TEST(Mapper, HandWorkedGenome) {
  const Grammar g = Grammar::parse(kSmall, "small.bnf");
  // <s>           -> <e>                           (one choice, no codon)
  // <e>  12 % 3 = 0 -> <e><op><e>
  // <e>   7 % 3 = 1 -> sin(<v>*2*PI*t)
  // <v>   5 % 3 = 2 -> 3                           sin(3*2*PI*t)
  // <op>  9 % 2 = 1 -> -
  // <e>   8 % 3 = 2 -> <v>
  // <v>   4 % 3 = 1 -> 2                           sin(3*2*PI*t)-2
  const Genome genome{12, 7, 5, 9, 8, 4, 99};
  const MapResult r = map_genome(g, genome);
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.phenotype, "sin(3*2*PI*t)-2");
  EXPECT_EQ(r.codons_used, 6);
  EXPECT_EQ(r.wraps, 0);
  EXPECT_EQ(r.depth, 4);  // s, e, e, v
  EXPECT_NO_THROW(Expression::compile(r.phenotype));
}

TEST(Mapper, WrapsAndGivesUpAfterMaxWraps) {
  const Grammar g = Grammar::parse(kSmall, "small.bnf");
  // {0, 1, 2}: <e>=0 -> <e><op><e>; <e>=1 -> sin(<v>...); <v>=2 -> 3; wrap:
  // <op>=0 -> +; <e>=1 -> sin; <v>=2 -> 3.
  const MapResult r = map_genome(g, Genome{0, 1, 2});
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.phenotype, "sin(3*2*PI*t)+sin(3*2*PI*t)");
  EXPECT_EQ(r.codons_used, 6);
  EXPECT_EQ(r.wraps, 1);
  // Always choosing the recursive production never finishes.
  const MapResult bad = map_genome(g, Genome{0, 0, 0}, MapLimits{3});
  EXPECT_FALSE(bad.valid);
  EXPECT_EQ(bad.codons_used, 12);  // 3 codons read 4 times
  EXPECT_FALSE(map_genome(g, Genome{}).valid);
  // No wrapping allowed: the wrapped genome above becomes invalid.
  EXPECT_FALSE(map_genome(g, Genome{0, 1, 2}, MapLimits{0}).valid);
}

TEST(Operators, InitialisationRampsDepthAndMapsValid) {
  const Grammar g = Grammar::parse(kSmall, "small.bnf");
  Rng rng(7);
  InitSettings s;
  s.max_depth = 6;
  const auto pop = ramped_full_grow(g, 40, s, rng);
  ASSERT_EQ(pop.size(), 40u);
  std::set<int> depths;
  for (const auto& genome : pop) {
    const MapResult r = map_genome(g, genome, MapLimits{0});  // no wrapping needed
    ASSERT_TRUE(r.valid);
    EXPECT_LE(r.depth, 6);
    depths.insert(r.depth);
    for (auto c : genome) EXPECT_LT(c, s.codon_size);
  }
  EXPECT_GE(depths.size(), 3u);  // the ramp gives a spread of depths
  // Full trees reach the requested depth.
  for (int d = 3; d <= 6; ++d) {
    const MapResult r = map_genome(g, derive_genome(g, d, false, s, rng), MapLimits{0});
    EXPECT_EQ(r.depth, d);
  }
}

TEST(Operators, CrossoverAndMutationKeepGenomesValid) {
  Rng rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    Genome a(1 + rng.below(20), 1), b(1 + rng.below(20), 2);
    const std::size_t la = a.size(), lb = b.size();
    fixed_point_crossover(a, b, 1.0, rng);
    EXPECT_EQ(a.size() + b.size(), la + lb);
    EXPECT_EQ(a.front(), 1u);  // the head stays
    EXPECT_EQ(b.front(), 2u);
    int_flip_mutation(a, 0.5, 100, rng);
    for (auto c : a) EXPECT_LT(c, 100u);
  }
  Genome a{1, 1, 1, 1}, b{2, 2, 2, 2};
  fixed_point_crossover(a, b, 0.0, rng);
  EXPECT_EQ(a, (Genome{1, 1, 1, 1}));
  Genome c{5, 5, 5};
  int_flip_mutation(c, 0.0, 100, rng);
  EXPECT_EQ(c, (Genome{5, 5, 5}));
}

TEST(Operators, TournamentPicksTheBestOfItsDraw) {
  Rng rng(11);
  const std::vector<double> fitness{5, 1, 9, 3};
  int wins_of_best = 0;
  for (int i = 0; i < 1000; ++i) wins_of_best += tournament(fitness, 3, rng) == 1;
  // P(index 1 drawn at least once in 3) = 1 - (3/4)^3 = 0.578.
  EXPECT_GT(wins_of_best, 500);
  EXPECT_LT(wins_of_best, 660);
  EXPECT_EQ(tournament(fitness, 100, rng), 1);
}

TEST(Operators, SameSeedSameNumbers) {
  Rng a(42), b(42);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(a.below(1000), b.below(1000));
}

}  // namespace
}  // namespace animrt::evolve
