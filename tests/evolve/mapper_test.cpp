// The GE mapping (worked by hand), wrapping, invalid individuals, and the
// genetic operators.

#include "animrt/learn/evolve/mapper.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/learn/evolve/operators.hpp"

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
  EXPECT_EQ(bad.wraps, 3);
  EXPECT_EQ(bad.phenotype, "");
  EXPECT_FALSE(map_genome(g, Genome{}).valid);
  // No wrapping allowed: the wrapped genome above becomes invalid.
  EXPECT_FALSE(map_genome(g, Genome{0, 1, 2}, MapLimits{0}).valid);
}

// Two curves, as the horse grammars' twelve: <c> takes one codon, <f> is
// recursive and so reads a variable number of codons; <sep> (the grammars'
// <newline>) makes no choice and gets no segment.
const char* kTwoCurves =
    "<p> ::= <c><sep><c>\n"
    "<sep> ::= ;\n"
    "<c> ::= <v> | <v>+<f>\n"
    "<f> ::= <f>+<f> | sin(<v>*t)\n"
    "<v> ::= 1 | 2 | 3\n";

TEST(Mapper, StructuredMapsEachCurveFromItsOwnSegment) {
  const Grammar g = Grammar::parse(kTwoCurves, "two.bnf");
  EXPECT_EQ(structured_segments(g), 2);
  // Segment 1 {1, 2, 1, 0}: <c> 1 -> <v>+<f>; <v> 2 -> 3; <f> 1 -> sin(<v>*t); <v> 0 -> 1.
  // Segment 2 {0, 1, 7, 7}: <c> 0 -> <v>; <v> 1 -> 2.
  const MapResult r = map_structured(g, Genome{1, 2, 1, 0, 0, 1, 7, 7});
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.phenotype, "3+sin(1*t);2");
  EXPECT_EQ(r.codons_used, 6);
  EXPECT_EQ(r.wraps, 0);
  EXPECT_EQ(r.depth, 4);  // p, c, f, v
  // Standard GE reads the same codons as one string: the second curve starts
  // where the first one stopped, at the 5th codon.
  EXPECT_EQ(map_genome(g, Genome{1, 2, 1, 0, 0, 1, 7, 7}).phenotype, "3+sin(1*t);2");
  // Make the first curve a plain number (codon 1: 1 -> 0), so that it reads two
  // codons instead of four. Standard GE's second curve now starts at the third
  // codon; structured GE's still reads its own segment.
  EXPECT_EQ(map_genome(g, Genome{0, 2, 1, 0, 0, 1, 7, 7}).phenotype, "3;1+sin(2*t)+sin(1*t)");
  EXPECT_EQ(map_structured(g, Genome{0, 2, 1, 0, 0, 1, 7, 7}).phenotype, "3;2");
}

TEST(Mapper, StructuredWrapsWithinASegmentAndRejectsBadShapes) {
  const Grammar g = Grammar::parse(kTwoCurves, "two.bnf");
  // Segment 1 {1, 2}: <c> 1 -> <v>+<f>; <v> 2 -> 3; wrap: <f> 1 -> sin(<v>*t);
  // <v> 2 -> 3. Segment 2 {0, 0}: <c> 0 -> <v>; <v> 0 -> 1.
  const MapResult r = map_structured(g, Genome{1, 2, 0, 0});
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.phenotype, "3+sin(3*t);1");
  EXPECT_EQ(r.wraps, 1);
  EXPECT_FALSE(map_structured(g, Genome{1, 2, 0, 0}, MapLimits{0}).valid);
  // A segment that never finishes ({1, 0, 0} keeps <f> recursive) fails the
  // genome, although the other segment maps.
  EXPECT_FALSE(map_structured(g, Genome{1, 0, 0, 0, 0, 0}).valid);
  EXPECT_TRUE(map_structured(g, Genome{0, 0, 0, 0, 0, 0}).valid);
  // The genome must split into whole segments.
  EXPECT_FALSE(map_structured(g, Genome{0, 0, 0}).valid);
  EXPECT_FALSE(map_structured(g, Genome{}).valid);
  // A start rule with several productions has no segments.
  const Grammar small = Grammar::parse("<e> ::= <e>+<e> | <v>\n<v> ::= 1 | 2\n", "choice.bnf");
  EXPECT_EQ(structured_segments(small), 0);
  EXPECT_FALSE(map_structured(small, Genome{0, 1, 1, 0}).valid);
}

TEST(Operators, StructuredInitialisationAlignsSegmentsThroughCrossover) {
  const Grammar g = Grammar::parse(kTwoCurves, "two.bnf");
  Rng rng(5);
  InitSettings s;
  s.max_depth = 6;
  const auto pop = ramped_structured(g, 30, s, rng);
  ASSERT_EQ(pop.size(), 30u);
  const std::size_t length = pop.front().size();
  ASSERT_EQ(length % 2, 0u);
  std::set<std::string> phenotypes;
  for (const auto& genome : pop) {
    EXPECT_EQ(genome.size(), length);
    const MapResult r = map_structured(g, genome, MapLimits{0});
    ASSERT_TRUE(r.valid);
    EXPECT_LE(r.depth, 6);
    phenotypes.insert(r.phenotype);
  }
  EXPECT_GT(phenotypes.size(), 10u);
  // Equal lengths: crossover keeps them, so a child's second curve is one of
  // its parents' second curves whenever the cut is in the first segment.
  Genome a = pop[0], b = pop[1];
  const std::string b_phenotype = map_structured(g, b).phenotype;
  const std::string second_b = b_phenotype.substr(b_phenotype.find(';'));
  int cuts_in_first = 0;
  for (int trial = 0; trial < 50; ++trial) {
    Genome x = a, y = b;
    fixed_point_crossover(x, y, 1.0, rng);
    ASSERT_EQ(x.size(), length);
    ASSERT_EQ(y.size(), length);
    // x took b's codons from the cut on; when its whole second segment is
    // b's, so is its second curve.
    if (!std::equal(x.begin() + static_cast<std::ptrdiff_t>(length / 2), x.end(),
                    b.begin() + static_cast<std::ptrdiff_t>(length / 2))) {
      continue;
    }
    ++cuts_in_first;
    const MapResult rx = map_structured(g, x);
    ASSERT_TRUE(rx.valid);
    EXPECT_EQ(rx.phenotype.substr(rx.phenotype.find(';')), second_b);
  }
  EXPECT_GT(cuts_in_first, 10);
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
