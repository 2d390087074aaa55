// Pareto ranking against hand-worked fronts, and the NSGA-II search on the
// quadruped: its front is non-dominated, repeatable, and the same however the
// walks are spread.

#include "animrt/learn/evolve/pareto.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/learn/evolve/pareto_search.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "support/files.hpp"

namespace animrt::evolve {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(Pareto, Dominance) {
  EXPECT_TRUE(dominates(std::vector{1.0, 2.0}, std::vector{1.0, 3.0}));
  EXPECT_TRUE(dominates(std::vector{0.0, 0.0}, std::vector{1.0, 1.0}));
  EXPECT_FALSE(dominates(std::vector{1.0, 2.0}, std::vector{1.0, 2.0}));  // equal
  EXPECT_FALSE(dominates(std::vector{1.0, 3.0}, std::vector{2.0, 1.0}));  // a trade-off
  EXPECT_FALSE(dominates(std::vector{2.0, 1.0}, std::vector{1.0, 3.0}));
}

// Seven points in two objectives, worked by hand:
//   0 (1,5) 1 (2,3) 2 (4,1)            none dominates another: front 0
//   3 (3,4) dominated by 1 only; 4 (5,2) dominated by 2 only: front 1
//   5 (5,5) dominated by 0,1,2,3,4: front 2
//   6 (1,5) a copy of 0: not dominated by it, so front 0
TEST(Pareto, FrontsOfAHandWorkedSet) {
  const std::vector<Objectives> p = {{1, 5}, {2, 3}, {4, 1}, {3, 4}, {5, 2}, {5, 5}, {1, 5}};
  const auto fronts = non_dominated_fronts(p);
  ASSERT_EQ(fronts.size(), 3u);
  EXPECT_EQ(fronts[0], (std::vector<int>{0, 1, 2, 6}));
  EXPECT_EQ(fronts[1], (std::vector<int>{3, 4}));
  EXPECT_EQ(fronts[2], (std::vector<int>{5}));
}

TEST(Pareto, UnwalkedPointsRankLast) {
  const std::vector<Objectives> p = {{kInf, kInf}, {9, 9}, {kInf, kInf}, {1, 20}};
  const auto fronts = non_dominated_fronts(p);
  ASSERT_EQ(fronts.size(), 2u);
  EXPECT_EQ(fronts[0], (std::vector<int>{1, 3}));
  EXPECT_EQ(fronts[1], (std::vector<int>{0, 2}));
  const auto d = crowding_distance(p, fronts[1]);
  EXPECT_TRUE(std::isinf(d[0]) || d[0] == 0.0);  // no NaN from inf - inf
  EXPECT_FALSE(std::isnan(d[1]));
}

// Front {(0,4), (1,2), (2,1), (4,0)}: spans 4 and 4. The extremes are
// infinite; (1,2) gets (2-0)/4 + (4-1)/4 = 1.25; (2,1) gets (4-1)/4 + (2-0)/4 = 1.25.
// Moving (2,1) to (3,0.5) crowds it toward (4,0):
// (1,2): (3-0)/4 + (4-0.5)/4 = 1.625; (3,0.5): (4-1)/4 + (2-0)/4 = 1.25.
TEST(Pareto, CrowdingDistanceOfAHandWorkedFront) {
  std::vector<Objectives> p = {{2, 1}, {0, 4}, {4, 0}, {1, 2}};
  const std::vector<int> front = {0, 1, 2, 3};
  auto d = crowding_distance(p, front);
  EXPECT_DOUBLE_EQ(d[0], 1.25);
  EXPECT_TRUE(std::isinf(d[1]));
  EXPECT_TRUE(std::isinf(d[2]));
  EXPECT_DOUBLE_EQ(d[3], 1.25);
  p[0] = {3, 0.5};
  d = crowding_distance(p, front);
  EXPECT_DOUBLE_EQ(d[0], 1.25);
  EXPECT_DOUBLE_EQ(d[3], 1.625);
  // Two members: both extremes.
  d = crowding_distance(p, std::vector<int>{1, 2});
  EXPECT_TRUE(std::isinf(d[0]) && std::isinf(d[1]));
}

class ParetoRun : public ::testing::Test {
 protected:
  static RunConfig config() {
    RunConfig c;
    c.name = "tiny";
    c.grammar = kSourceRoot + "/configs/grammars/quadruped_hybrid.bnf";
    c.model = kSourceRoot + "/configs/models/quadruped.xml";
    c.seed_gait = kSourceRoot + "/configs/gaits/quadruped_seed.yaml";
    c.search.seed = 3;
    c.search.population = 8;
    c.search.generations = 2;
    c.search.init.max_depth = 6;
    c.walk.settle_s = 0.2;
    c.walk.warmup_cycles = 1;
    c.walk.measure_cycles = 1;
    c.weights.push_back({});
    return c;
  }
  ParetoResult run(int threads) {
    const RunConfig c = config();
    sim::MujocoGaitSimulatorFactory factory(c.model);
    ThreadEvaluator evaluator(factory, threads);
    ModelInfo info{factory.model().actuated_joints, factory.model().hip_height_m,
                   factory.model().mass_kg};
    ParetoSearch search(c, Grammar::load_file(c.grammar), load_gait_file(c.seed_gait), info,
                        evaluator);
    return search.run();
  }
};

TEST_F(ParetoRun, TheFrontIsNonDominatedAndTheSameOnOneOrTwoThreads) {
  const ParetoResult one = run(1);
  ASSERT_EQ(one.history.size(), 3u);
  ASSERT_FALSE(one.front.empty());
  for (const auto& a : one.front) {
    ASSERT_EQ(a.objectives.size(), static_cast<std::size_t>(kParetoObjectives));
    EXPECT_FALSE(a.individual.measures.fell);
    for (double v : a.objectives) EXPECT_TRUE(std::isfinite(v));
    EXPECT_GT(a.objectives[2], 0.0);  // a walking torso tilts a little
    for (const auto& b : one.front) EXPECT_FALSE(dominates(b.objectives, a.objectives));
  }
  for (std::size_t i = 1; i < one.front.size(); ++i) {
    EXPECT_LE(one.front[i - 1].objectives[0], one.front[i].objectives[0]);
    EXPECT_NE(one.front[i - 1].individual.phenotype, one.front[i].individual.phenotype);
  }
  const ParetoResult two = run(2);
  ASSERT_EQ(two.front.size(), one.front.size());
  for (std::size_t i = 0; i < one.front.size(); ++i) {
    EXPECT_EQ(two.front[i].individual.phenotype, one.front[i].individual.phenotype);
    EXPECT_EQ(two.front[i].objectives, one.front[i].objectives);
  }
}

}  // namespace
}  // namespace animrt::evolve
