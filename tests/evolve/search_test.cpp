// The GE search: reproducible from its seed, threads agree with a serial run,
// invalid individuals score worst and are counted, a falling phenotype gets
// the worst score, the run file is checked.

#include "animrt/learn/evolve/search.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>

#include "animrt/learn/evolve/evaluator.hpp"
#include "animrt/learn/evolve/phenotype.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "support/files.hpp"

namespace animrt::evolve {
namespace {

// A tiny run on the demo quadruped: short walks, few individuals.
RunConfig tiny_run() {
  RunConfig c = load_run_config(kSourceRoot + "/configs/evolve/quadruped_concatenating.yaml");
  c.search.population = 8;
  c.search.generations = 2;
  c.search.elites = 2;
  c.search.init.max_depth = 6;
  c.walk.settle_s = 0.1;
  c.walk.warmup_cycles = 1;
  c.walk.measure_cycles = 1;
  return c;
}

SearchResult run_with(const RunConfig& c, Evaluator& evaluator, const ModelInfo& info) {
  Search search(c, Grammar::load_file(c.grammar), load_gait_file(c.seed_gait), info, evaluator);
  return search.run();
}

void expect_same(const SearchResult& a, const SearchResult& b) {
  ASSERT_EQ(a.history.size(), b.history.size());
  for (std::size_t g = 0; g < a.history.size(); ++g) {
    EXPECT_EQ(a.history[g].best, b.history[g].best) << "generation " << g;
    EXPECT_EQ(a.history[g].average, b.history[g].average) << "generation " << g;
    EXPECT_EQ(a.history[g].invalid, b.history[g].invalid) << "generation " << g;
    EXPECT_EQ(a.history[g].best_phenotype, b.history[g].best_phenotype) << "generation " << g;
  }
  EXPECT_EQ(a.best.phenotype, b.best.phenotype);
  EXPECT_EQ(format_gait_file(a.best.gait), format_gait_file(b.best.gait));
}

TEST(Search, SameSeedSameRunAndThreadsAgreeWithSerial) {
  const RunConfig c = tiny_run();
  sim::MujocoGaitSimulatorFactory factory(c.model);
  const ModelInfo info{factory.model().actuated_joints, factory.model().hip_height_m,
                       factory.model().mass_kg};
  ThreadEvaluator serial(factory, 1);
  ThreadEvaluator threads(factory, 2);
  const SearchResult a = run_with(c, serial, info);
  const SearchResult b = run_with(c, serial, info);
  const SearchResult t = run_with(c, threads, info);
  expect_same(a, b);
  expect_same(a, t);
  ASSERT_EQ(a.history.size(), 3u);  // generations 0, 1, 2
  // Elitism: with fixed weights the best never gets worse.
  EXPECT_LE(a.history[2].best, a.history[0].best);
  EXPECT_TRUE(a.best.valid);
  EXPECT_LT(a.best.fitness, kWorstFitness);
}

TEST(Search, FallingPhenotypeGetsTheWorstScore) {
  const RunConfig c = tiny_run();
  sim::MujocoGaitSimulatorFactory factory(c.model);
  auto sim = factory.make();
  const GaitFile seed = load_gait_file(c.seed_gait);
  const PhenotypeGait flail =
      make_phenotype_gait(seed, "200*sin(2*PI*t); 200*sin(2*PI*t); 200*sin(2*PI*t)");
  ASSERT_TRUE(flail.valid) << flail.error;
  const GaitMeasures m = sim->walk(flail.gait, c.walk);
  EXPECT_TRUE(m.fell);
  const GaitTargets t = froude_targets(seed.froude->number, seed.froude->hip_height_m);
  EXPECT_EQ(score(m, t, {}, sim->info().mass_kg), kWorstFitness);
  // The seed itself scores better than worst.
  EXPECT_LT(score(sim->walk(seed, c.walk), t, {}, sim->info().mass_kg), kWorstFitness);
}

// Walks nothing: each gait's measures come from `measure` (by default the
// same for every gait); counts the walks.
class FakeEvaluator final : public Evaluator {
 public:
  using Measure = std::function<GaitMeasures(const GaitFile&)>;
  FakeEvaluator() = default;
  explicit FakeEvaluator(Measure measure) : measure_(std::move(measure)) {}
  void walk_all(std::span<const GaitFile* const> gaits, const WalkSettings&,
                std::span<GaitMeasures> out) override {
    for (std::size_t i = 0; i < gaits.size(); ++i) {
      out[i] = measure_(*gaits[i]);
      ++walked;
    }
  }
  int workers() const override { return 1; }
  int walked = 0;

 private:
  Measure measure_ = [](const GaitFile&) {
    GaitMeasures m;
    m.speed = 0.05;
    m.stride_length = 0.05;
    m.duty_factor = 0.7;
    return m;
  };
};

TEST(Search, InvalidIndividualsScoreWorstAndAreCounted) {
  RunConfig c = tiny_run();
  c.search.population = 20;
  c.search.generations = 0;
  // A curve that is infinite makes the phenotype an unusable gait.
  const Grammar g = Grammar::parse(
      "<p> ::= <c>;<c>;<c>\n<c> ::= 1e308*1e308 | sin(2*PI*t) | 2*sin(2*PI*t)\n", "inv.bnf");
  Rng rng(c.search.seed);
  int expected_invalid = 0;
  std::set<std::string> valid_phenotypes;  // each is walked once
  for (const auto& genome : ramped_full_grow(g, c.search.population, c.search.init, rng)) {
    const MapResult r = map_genome(g, genome);
    if (r.phenotype.find("1e308") != std::string::npos) {
      ++expected_invalid;
    } else {
      valid_phenotypes.insert(r.phenotype);
    }
  }
  ASSERT_GT(expected_invalid, 0);
  ASSERT_LT(expected_invalid, c.search.population);
  const int valid = c.search.population - expected_invalid;
  ASSERT_LT(static_cast<int>(valid_phenotypes.size()), valid);  // some repeat (8 possible)
  FakeEvaluator fake;
  Search search(c, g, load_gait_file(c.seed_gait), {{}, 0.18, 1.6}, fake);
  const SearchResult r = search.run();
  EXPECT_EQ(r.history[0].invalid, expected_invalid);
  EXPECT_EQ(fake.walked, static_cast<int>(valid_phenotypes.size()));
  EXPECT_EQ(r.history[0].evaluations, fake.walked);
  EXPECT_EQ(r.history[0].reused, valid - fake.walked);
  const double valid_score = r.history[0].best;
  EXPECT_LT(valid_score, kWorstFitness);
  const double n = c.search.population;
  EXPECT_NEAR(r.history[0].average,
              ((n - expected_invalid) * valid_score + expected_invalid * kWorstFitness) / n, 1e-6);
}

TEST(Search, StructuredMappingNeedsOneStartProductionAndMapsEveryCurve) {
  RunConfig c = tiny_run();
  c.search.population = 12;
  c.search.generations = 1;
  c.search.mapping = Mapping::structured;
  const GaitFile seed = load_gait_file(c.seed_gait);
  // Every curve's segment maps, so nobody is invalid, and the children of
  // crossover still split into three segments.
  const Grammar g = Grammar::parse(
      "<p> ::= <c>;<c>;<c>\n<c> ::= <c>+<c> | sin(2*PI*t) | 2*sin(2*PI*t)\n", "three.bnf");
  FakeEvaluator fake;
  const SearchResult r = Search(c, g, seed, {{}, 0.18, 1.6}, fake).run();
  ASSERT_EQ(r.history.size(), 2u);
  EXPECT_EQ(r.history[0].invalid, 0);
  EXPECT_EQ(r.history[1].invalid, 0);
  EXPECT_EQ(r.best.genome.size() % 3, 0u);
  EXPECT_EQ(map_structured(g, r.best.genome).phenotype, r.best.phenotype);
  EXPECT_NE(map_genome(g, r.best.genome).phenotype, r.best.phenotype);
  // A start rule with a choice cannot be cut into curves.
  const Grammar choice = Grammar::parse(
      "<p> ::= <c>;<c>;<c> | <c>;<c>;<c>\n<c> ::= sin(2*PI*t) | 2*sin(2*PI*t)\n", "choice.bnf");
  c.search.mapping_where = {"run.yaml", 7, 12};
  const auto error_of = [&](const Grammar& grammar) {
    try {
      Search(c, grammar, seed, {{}, 0.18, 1.6}, fake);
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), "search.mapping");
      EXPECT_EQ(e.where().line, 7);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of(choice).find("<p> in choice.bnf has 2 productions"), std::string::npos)
      << error_of(choice);
  // Nothing in the start rule makes a choice: there is nothing to segment.
  const Grammar fixed = Grammar::parse("<p> ::= <c>;<c>;<c>\n<c> ::= sin(2*PI*t)\n", "fixed.bnf");
  EXPECT_NE(error_of(fixed).find("no codon segments"), std::string::npos) << error_of(fixed);
}

// Measures from every curve of the gait, held ones included, so that one
// phenotype walks differently under another freedom stage.
GaitMeasures from_curves(const GaitFile& gait) {
  std::size_t chars = 0;
  for (const auto& curve : gait.curves) chars += curve.expression.size();
  GaitMeasures m;
  m.speed = 0.001 * static_cast<double>(chars);
  m.stride_length = 0.05;
  m.duty_factor = 0.7 - 0.001 * static_cast<double>(gait.curves[0].expression.size());
  return m;
}

TEST(Search, RepeatedGaitsAreNotWalkedAgainAndTheRunIsTheSame) {
  RunConfig c = tiny_run();
  c.search.population = 30;
  c.search.generations = 6;
  const GaitFile seed = load_gait_file(c.seed_gait);
  ASSERT_EQ(seed.curves.size(), 3u);
  // First one curve free, the others held at their seed means; all from 3 on.
  c.freedom = {{0, {seed.curves[0].name}, {}},
               {3, {seed.curves[0].name, seed.curves[1].name, seed.curves[2].name}, {}}};
  const Grammar g = Grammar::parse(
      "<p> ::= <c>;<c>;<c>\n<c> ::= <c>+<c> | sin(2*PI*t) | 2*sin(2*PI*t) | 0.5\n", "four.bnf");
  FakeEvaluator remembering(from_curves);
  const SearchResult a = Search(c, g, seed, {{}, 0.18, 1.6}, remembering).run();
  c.search.remember_walks = false;
  FakeEvaluator walking_all(from_curves);
  const SearchResult b = Search(c, g, seed, {{}, 0.18, 1.6}, walking_all).run();
  expect_same(a, b);
  for (std::size_t gen = 0; gen < a.history.size(); ++gen) {
    EXPECT_EQ(a.history[gen].fell, b.history[gen].fell) << gen;
    EXPECT_EQ(a.history[gen].evaluations + a.history[gen].reused, b.history[gen].evaluations)
        << gen;
    EXPECT_EQ(b.history[gen].reused, 0) << gen;
  }
  EXPECT_EQ(remembering.walked, a.evaluations);
  EXPECT_GT(a.reused, 0);
  EXPECT_LT(remembering.walked, walking_all.walked);
  // Elites keep their walk, except at the change of stage: under the new one
  // they are walked again.
  EXPECT_EQ(b.history[2].evaluations + b.history[2].invalid, c.search.population - c.search.elites);
  EXPECT_EQ(b.history[3].evaluations + b.history[3].invalid, c.search.population);
}

TEST(Search, ASeedGaitWithoutFroudeTimingIsRefused) {
  const RunConfig c = tiny_run();
  GaitFile seed = load_gait_file(c.seed_gait);
  seed.froude.reset();
  FakeEvaluator fake;
  try {
    Search(c, Grammar::load_file(c.grammar), seed, {{}, 0.18, 1.6}, fake);
    ADD_FAILURE() << "a seed without froude timing was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "froude");
    EXPECT_EQ(e.where().file, c.seed_gait);
  }
}

TEST(Search, HooksSeeEveryGenerationAndItsBestAndStopEndsTheRunThere) {
  RunConfig c = tiny_run();
  c.search.generations = 10;
  FakeEvaluator fake;
  Search search(c, Grammar::load_file(c.grammar), load_gait_file(c.seed_gait), {{}, 0.18, 1.6},
                fake);
  std::vector<int> seen;
  int asked = 0;
  SearchHooks hooks;
  hooks.generation = [&](const GenerationStats& st, const Individual& best) {
    seen.push_back(st.generation);
    EXPECT_EQ(best.fitness, st.best);
    EXPECT_EQ(best.phenotype, st.best_phenotype);
  };
  hooks.stop = [&] { return ++asked == 3; };  // after generation 2
  const SearchResult r = search.run(hooks);
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(seen, (std::vector<int>{0, 1, 2}));
  ASSERT_EQ(r.history.size(), 3u);
  EXPECT_EQ(r.best.fitness, r.history.back().best);
  EXPECT_TRUE(r.best.valid);
  // Never asked after the last generation: a run that is not stopped ends as before.
  c.search.generations = 1;
  Search whole(c, Grammar::load_file(c.grammar), load_gait_file(c.seed_gait), {{}, 0.18, 1.6},
               fake);
  asked = 0;
  hooks.generation = {};
  hooks.stop = [&] { return ++asked > 1; };
  const SearchResult w = whole.run(hooks);
  EXPECT_FALSE(w.stopped);
  EXPECT_EQ(w.history.size(), 2u);
  EXPECT_EQ(asked, 1);
}

TEST(Phenotype, WrongCurveCountOrBadExpressionIsInvalid) {
  const GaitFile seed = load_gait_file(kSourceRoot + "/configs/gaits/quadruped_seed.yaml");
  EXPECT_FALSE(make_phenotype_gait(seed, "1;2").valid);
  EXPECT_FALSE(make_phenotype_gait(seed, "1;2;(3").valid);
  const PhenotypeGait ok = make_phenotype_gait(seed, "1 + 2*t; 2; 3", {"", "7", ""});
  ASSERT_TRUE(ok.valid) << ok.error;
  EXPECT_EQ(ok.gait.curves[1].expression, "7");  // held still
  EXPECT_EQ(ok.gait.joints.size(), seed.joints.size());
}

TEST(RunConfig, ErrorsNameFileLineAndKey) {
  const auto error_of = [](const std::string& text) {
    try {
      parse_run_config(text, "run.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head = "name: x\ngrammar: g.bnf\nmodel: m.xml\nseed_gait: s.yaml\n";
  EXPECT_EQ(error_of(head + "search: {population: 1}\n"),
            "run.yaml:5:22: search.population: expected an integer from 2 to 1000000, found \"1\"");
  EXPECT_EQ(error_of(head + "bogus: 1\n"),
            "run.yaml:5:1: bogus: unknown key (expected one of: name, grammar, model, seed_gait, "
            "robot, search, walk, fitness, threads)");
  EXPECT_EQ(error_of(head + "fitness: {weights: [{from_generation: 3}]}\n"),
            "run.yaml:5:39: fitness.weights[0].from_generation: the first stage must start at "
            "generation 0");
  // A stage whose weights are all 0 ranks every gait the same; no stage at all
  // is not the defaults either.
  EXPECT_EQ(error_of(head + "fitness: {weights: [{from_generation: 0, distance: 0, "
                            "duty_factor: 0, stride_length: 0, energy: 0}]}\n"),
            "run.yaml:5:21: fitness.weights[0]: every weight is 0: the stage would rank every "
            "gait the same");
  EXPECT_EQ(error_of(head + "fitness: {weights: []}\n"),
            "run.yaml:5:20: fitness.weights: expected at least one stage (leave weights out for "
            "the defaults)");
  EXPECT_EQ(error_of(head + "fitness: {weights: [{from_generation: 0, distance: 0}]}\n"),
            "no error");
  EXPECT_EQ(error_of(head + "search: {mapping: tree}\n"),
            "run.yaml:5:19: search.mapping: expected standard or structured, got 'tree'");
  EXPECT_EQ(parse_run_config(head + "search: {mapping: structured}\n", "run.yaml").search.mapping,
            Mapping::structured);
  EXPECT_FALSE(parse_run_config(head + "search: {remember_walks: false}\n", "run.yaml")
                   .search.remember_walks);
  const RunConfig ok = parse_run_config(head, "/a/b/run.yaml");
  EXPECT_EQ(ok.search.mapping, Mapping::standard);
  EXPECT_TRUE(ok.search.remember_walks);
  EXPECT_EQ(ok.grammar, "/a/b/g.bnf");
  EXPECT_EQ(ok.robot, "");  // the walk as the physics alone plays it
  EXPECT_EQ(parse_run_config(head + "robot: ../r.yaml\n", "/a/b/run.yaml").robot, "/a/r.yaml");
  EXPECT_EQ(ok.search.population, 75);
  EXPECT_EQ(ok.search.elites, 7);
  ASSERT_EQ(ok.weights.size(), 1u);
}

TEST(RunConfig, MissingModelIsReportedAtItsKey) {
  const std::string dir = ::testing::TempDir() + "/run_config_missing_model";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/run.yaml";
  std::ofstream(path) << "name: x\ngrammar: " << kSourceRoot
                      << "/configs/grammars/quadruped_free.bnf\nmodel: ../models/nope.xml\n"
                         "seed_gait: "
                      << kSourceRoot << "/configs/gaits/quadruped_seed.yaml\n";
  try {
    (void)load_run_config(path);
    ADD_FAILURE() << "missing model accepted";
  } catch (const InputError& e) {
    const std::string model =
        (std::filesystem::path(dir) / ".." / "models" / "nope.xml").lexically_normal().string();
    EXPECT_EQ(std::string(e.what()), path + ":3:8: model: \"" + model + "\" does not exist");
  }
  std::filesystem::remove_all(dir);
}

TEST(RunConfig, ShippedRunFilesLoad) {
  for (const char* f :
       {"horse_numerical", "horse_concatenating", "horse_hybrid", "horse_sinusoidal", "horse_free",
        "horse_concatenating_varying_weights", "horse_concatenating_varying_freedom",
        "horse_hybrid_structured", "horse_numerical_balance", "horse_hybrid_balance",
        "horse_hybrid_structured_balance", "quadruped_concatenating"}) {
    const RunConfig c = load_run_config(kSourceRoot + "/configs/evolve/" + f + ".yaml");
    EXPECT_NO_THROW(Grammar::load_file(c.grammar)) << f;
    EXPECT_NO_THROW(load_gait_file(c.seed_gait)) << f;
    // The balance runs walk their seed with the reflex, and only they.
    const bool balance = std::string(f).find("_balance") != std::string::npos;
    EXPECT_EQ(load_gait_file(c.seed_gait).balance.has_value(), balance) << f;
  }
  const RunConfig h = load_run_config(kSourceRoot + "/configs/evolve/horse_hybrid_structured.yaml");
  EXPECT_EQ(h.search.mapping, Mapping::structured);
  EXPECT_EQ(structured_segments(Grammar::load_file(h.grammar)), 12);
  const RunConfig w =
      load_run_config(kSourceRoot + "/configs/evolve/horse_concatenating_varying_weights.yaml");
  ASSERT_EQ(w.weights.size(), 5u);
  EXPECT_EQ(weights_at(w.weights, 15).distance, 2.0);
  EXPECT_EQ(weights_at(w.weights, 25).duty_factor, 2.0);
  EXPECT_EQ(weights_at(w.weights, 50).stride_length, 1.0);
  const RunConfig f =
      load_run_config(kSourceRoot + "/configs/evolve/horse_concatenating_varying_freedom.yaml");
  ASSERT_EQ(f.freedom.size(), 4u);
  EXPECT_EQ(f.freedom[0].free.size(), 3u);
  EXPECT_EQ(f.freedom[3].free.size(), 12u);
}

}  // namespace
}  // namespace animrt::evolve
