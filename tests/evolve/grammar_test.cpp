// BNF grammar parsing: the paper's grammars load; every kind of bad grammar
// gets one error naming file, line, column and rule.

#include "animrt/learn/evolve/grammar.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/evolve/mapper.hpp"
#include "animrt/learn/evolve/random.hpp"
#include "support/files.hpp"

namespace animrt::evolve {
namespace {

std::string error_of(const std::string& text) {
  try {
    Grammar::parse(text, "g.bnf");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Grammar, ParsesRulesProductionsAndContinuationLines) {
  const Grammar g = Grammar::parse(
      "# comment\n"
      "<e> ::= <e> + <v> | <v>   # trailing comment\n"
      "      | (<e>)\n"
      "<v> ::= t | 1\n",
      "g.bnf");
  ASSERT_EQ(g.rules().size(), 2u);
  EXPECT_EQ(g.start().name, "e");
  ASSERT_EQ(g.rules()[0].productions.size(), 3u);
  const auto& first = g.rules()[0].productions[0].symbols;
  ASSERT_EQ(first.size(), 3u);
  EXPECT_FALSE(first[0].terminal);
  EXPECT_EQ(first[0].rule, 0);
  EXPECT_EQ(first[1].text, " + ");
  EXPECT_EQ(first[2].rule, 1);
  EXPECT_TRUE(g.rules()[0].productions[0].recursive);
  EXPECT_FALSE(g.rules()[0].productions[1].recursive);
  EXPECT_EQ(g.rules()[1].min_depth, 1);
  EXPECT_EQ(g.rules()[0].min_depth, 2);
}

TEST(Grammar, ExpandsCompactRanges) {
  const Grammar g = Grammar::parse("<a> ::= 0 | 0.25 | ... | 1 | x\n", "g.bnf");
  std::vector<std::string> values;
  for (const auto& p : g.start().productions) values.push_back(p.symbols[0].text);
  EXPECT_EQ(values, (std::vector<std::string>{"0", "0.25", "0.50", "0.75", "1", "x"}));
  const Grammar neg = Grammar::parse("<a> ::= -1.5 | -1.2 | ... | -0.3\n", "g.bnf");
  EXPECT_EQ(neg.start().productions.size(), 5u);
  EXPECT_EQ(neg.start().productions[2].symbols[0].text, "-0.9");
}

TEST(Grammar, ErrorsNameFileLineColumnAndRule) {
  EXPECT_EQ(error_of("<a> ::= <b> | x\n"), "g.bnf:1:9: <a>: undefined non-terminal <b>");
  EXPECT_EQ(error_of("<a> ::= x\n<b> ::= y\n"),
            "g.bnf:2:1: <b>: unreachable from the start rule <a>");
  EXPECT_EQ(error_of("<a> ::= <b> | x\n<b> ::= <b> x | (<b>)\n"),
            "g.bnf:2:1: <b>: recursion with no terminal exit: every production leads back to it");
  EXPECT_EQ(error_of("<a> x\n"), "g.bnf:1:1: expected '<name> ::= ...'");
  EXPECT_EQ(error_of("<a> ::= x\nfoo\n"),
            "g.bnf:2:1: expected '<name> ::= ...' or a line starting with '|'");
  EXPECT_EQ(error_of("<a> ::= x || y\n"), "g.bnf:1:12: <a>: empty production");
  EXPECT_EQ(error_of("<a> ::= <b\n"),
            "g.bnf:1:9: <a>: expected a non-terminal name and '>' after '<'");
  EXPECT_EQ(error_of("<a> ::= x\n<a> ::= y\n"),
            "g.bnf:2:1: <a>: rule defined twice (first at line 1)");
  EXPECT_EQ(
      error_of("<a> ::= 0 | ... | 1\n"),
      "g.bnf:1:13: <a>: '...' needs two numbers before it and one after (e.g. 0 | 0.5 | ... | 4)");
  EXPECT_EQ(error_of("<a> ::= 0 | 0.3 | ... | 1\n"),
            "g.bnf:1:19: <a>: range 0 | 0.3 | ... | 1 does not reach its end in whole steps");
  EXPECT_EQ(error_of(""), "g.bnf: the grammar has no rules");
}

TEST(Grammar, LoadsEveryShippedGrammar) {
  for (const char* model : {"horse", "quadruped"}) {
    for (const char* style : {"numerical", "concatenating", "hybrid", "sinusoidal", "free"}) {
      const std::string path = kSourceRoot + "/configs/grammars/" + model + "_" + style + ".bnf";
      EXPECT_NO_THROW(Grammar::load_file(path)) << path;
    }
  }
  const Grammar g = Grammar::load_file(kSourceRoot + "/configs/grammars/horse_concatenating.bnf");
  EXPECT_EQ(g.rules()[static_cast<std::size_t>(g.find("low_amp_var"))].productions.size(), 81u);
  EXPECT_EQ(g.rules()[static_cast<std::size_t>(g.find("med_amp_var"))].productions.size(), 41u);
  EXPECT_EQ(g.rules()[static_cast<std::size_t>(g.find("hi_amp_var"))].productions.size(), 21u);
}

// Every curve a sine-based grammar can build repeats each stride (t is in
// stride cycles): the fitness measures whole cycles, left and right legs play
// one curve half a stride apart, and the runtime loops the gait. A frequency
// that is not a whole harmonic (the numerical grammars once varied 1 to
// 0.75..1.25) breaks all three.
TEST(Grammar, EveryCurveOfTheSeededAndSinusoidalGrammarsRepeatsEachStride) {
  for (const char* model : {"horse", "quadruped"}) {
    for (const char* style : {"numerical", "concatenating", "hybrid", "sinusoidal"}) {
      const std::string path = kSourceRoot + "/configs/grammars/" + model + "_" + style + ".bnf";
      const Grammar g = Grammar::load_file(path);
      Rng rng(11);
      int checked = 0;
      for (int individual = 0; individual < 40; ++individual) {
        Genome genome(400);
        for (auto& codon : genome) codon = static_cast<std::uint32_t>(rng.below(65536));
        const MapResult r = map_genome(g, genome);
        if (!r.valid) continue;
        std::stringstream curves(r.phenotype);
        std::string text;
        while (std::getline(curves, text, ';')) {
          const Expression curve = Expression::compile(text);
          for (double t : {0.0, 0.13, 0.5, 0.77}) {
            EXPECT_NEAR(curve.eval(t + 1.0), curve.eval(t), 1e-6) << path << ": " << text;
            EXPECT_NEAR(curve.eval(t + 3.0), curve.eval(t), 1e-6) << path << ": " << text;
          }
        }
        ++checked;
      }
      EXPECT_GE(checked, 10) << path;
    }
  }
}

TEST(Grammar, MissingFileIsAnInputError) {
  EXPECT_THROW(Grammar::load_file("/nonexistent.bnf"), InputError);
}

TEST(Grammar, HugeGrammarOfUnreachableRulesIsRejected) {
  // 200,000 rules, each defined once and none used by the start rule: the
  // duplicate, undefined-rule and reachability checks must not compare every
  // rule with every other.
  constexpr int kRules = 200000;
  std::string text = "<start> ::= <r0> | x\n<r0> ::= y\n";
  for (int i = 1; i <= kRules; ++i)
    text += "<r" + std::to_string(i) + "> ::= <r" + std::to_string(i - 1) + "> | z\n";
  EXPECT_EQ(error_of(text), "g.bnf:3:1: <r1>: unreachable from the start rule <start>");
  // The same rules chained from the start: all reachable, all recursive-free.
  std::string chained = "<start> ::= <r" + std::to_string(kRules) + ">\n<r0> ::= y\n";
  for (int i = 1; i <= kRules; ++i)
    chained += "<r" + std::to_string(i) + "> ::= <r" + std::to_string(i - 1) + "> | z\n";
  const Grammar g = Grammar::parse(chained, "g.bnf");
  ASSERT_EQ(g.rules().size(), static_cast<std::size_t>(kRules) + 2);
  EXPECT_EQ(g.start().min_depth, 2);  // start -> r200000 -> z
  EXPECT_FALSE(g.start().recursive);
}

TEST(Grammar, DepthsAndRecursionOfAMutuallyRecursiveGrammar) {
  const Grammar g = Grammar::parse(
      "<e> ::= <a> | <b>\n"
      "<a> ::= (<b>) | <c>\n"
      "<b> ::= [<a>]\n"
      "<c> ::= <d> <d>\n"
      "<d> ::= t\n",
      "g.bnf");
  const auto& r = g.rules();
  EXPECT_EQ(r[4].min_depth, 1);  // d
  EXPECT_EQ(r[3].min_depth, 2);  // c
  EXPECT_EQ(r[1].min_depth, 3);  // a via c
  EXPECT_EQ(r[2].min_depth, 4);  // b via a
  EXPECT_EQ(r[0].min_depth, 4);  // e via a
  EXPECT_EQ(r[1].productions[0].min_depth, 5);
  EXPECT_TRUE(r[1].productions[0].recursive);   // a -> b -> a
  EXPECT_FALSE(r[1].productions[1].recursive);  // a -> c
  EXPECT_TRUE(r[2].productions[0].recursive);
  EXPECT_FALSE(r[0].recursive);  // nothing leads back to e
  EXPECT_FALSE(r[3].recursive);
  EXPECT_EQ(error_of("<e> ::= <a>\n<a> ::= (<b>)\n<b> ::= [<a>]\n"),
            "g.bnf:1:1: <e>: recursion with no terminal exit: every production leads back to it");
}

}  // namespace
}  // namespace animrt::evolve
