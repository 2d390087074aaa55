// Counterflow: two teams cross each other through the one 2 m gap of a
// wall (about four figure widths), each to a target on the far side. The
// gap is a narrow passage: the teams take turns, one waiting beside the
// mouth while the other passes.
#include <gtest/gtest.h>

#include <cstdio>

#include "animrt/controllers/herd/passage.hpp"
#include "herd/crowd_sim.hpp"

namespace animrt::herd {
namespace {

NavWorldConfig one_gap_world(double gap) {
  NavWorldConfig c;
  c.bounds = {-14, -7, 14, 7};
  const double h = (14 - gap) / 2;  // each wall part, from the gap to the edge
  c.walls = {{{0, -gap / 2 - h / 2}, {0.5, h}, 0.0}, {{0, gap / 2 + h / 2}, {0.5, h}, 0.0}};
  c.agent_radius_m = 0.25;
  return c;
}

struct FlowResult {
  int collisions = 0;
  std::size_t arrived = 0, agents = 0;
  double max_time_ratio = 0.0;
};

// A corridor 4 m long and `width` wide through the wall at x = 0.
NavWorldConfig corridor_world(double width) {
  NavWorldConfig c;
  c.bounds = {-14, -7, 14, 7};
  const double h = (14 - width) / 2;
  c.walls = {{{0, -width / 2 - h / 2}, {4, h}, 0.0}, {{0, width / 2 + h / 2}, {4, h}, 0.0}};
  c.agent_radius_m = 0.25;
  return c;
}

FlowResult run_counterflow(int per_team, std::uint64_t seed, double t_max, CrowdParams params,
                           const NavWorldConfig& config = one_gap_world(2.0)) {
  NavWorld world(config);
  std::vector<Agent> agents;
  std::mt19937_64 rng(seed);
  test::spawn(agents, per_team, {-12, -4, -7, 4}, 0.25, 0.8, 0.0, 0, rng);
  test::spawn(agents, per_team, {7, -4, 12, 4}, 0.25, 0.8, M_PI, 1, rng);
  Crowd crowd(world, agents, params);
  std::vector<int> red, blue;
  for (int i = 0; i < per_team; ++i) {
    red.push_back(i);
    blue.push_back(per_team + i);
  }
  const Vec2 red_goal{9, 0}, blue_goal{-9, 0};
  CrowdGroup g_red(crowd, agents, red, {red_goal, 0.10, 0.13, seed * 2 + 1});
  CrowdGroup g_blue(crowd, agents, blue, {blue_goal, 0.10, 0.13, seed * 2 + 2});
  std::vector<double> vmax(agents.size()), ideal(agents.size()), arrival(agents.size(), -1.0);
  for (std::size_t k = 0; k < red.size(); ++k) {
    vmax[static_cast<std::size_t>(red[k])] = g_red.max_speed(k);
    vmax[static_cast<std::size_t>(blue[k])] = g_blue.max_speed(k);
  }
  for (std::size_t i = 0; i < agents.size(); ++i) {
    ideal[i] = norm((agents[i].group == 0 ? red_goal : blue_goal) - agents[i].position) / vmax[i];
  }
  std::vector<Vec2> desired(agents.size());
  FlowResult res;
  res.agents = agents.size();
  const double dt = 0.1;
  for (double t = 0.0; t < t_max; t += dt) {
    g_red.steer(t, dt, agents, desired);
    g_blue.steer(t, dt, agents, desired);
    // Slow-turning figures: 15 degrees a second, as the pony.
    test::move_figures(agents, desired, vmax, dt, 0.26);
    res.collisions += test::count_collisions(agents);
    for (std::size_t k = 0; k < red.size(); ++k) {
      for (auto [g, m] : {std::pair{&g_red, red[k]}, std::pair{&g_blue, blue[k]}}) {
        if (g->arrived(k) && arrival[static_cast<std::size_t>(m)] < 0) {
          arrival[static_cast<std::size_t>(m)] = t + dt;
        }
      }
    }
    if (g_red.arrived_count() + g_blue.arrived_count() == agents.size()) break;
  }
  res.arrived = g_red.arrived_count() + g_blue.arrived_count();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const double ta = arrival[i] < 0 ? t_max : arrival[i];
    res.max_time_ratio = std::max(res.max_time_ratio, ta / ideal[i]);
  }
  std::printf("%d per team, seed %llu: arrived %zu/%zu, max time ratio %.2f, collisions %d\n",
              per_team, static_cast<unsigned long long>(seed), res.arrived, res.agents,
              res.max_time_ratio, res.collisions);
  return res;
}

// Both teams arrive within three times their straight-line time, and no
// two figures ever touch, for several seeds and team sizes.
TEST(CrowdCounterflow, TeamsTakeTurnsThroughOneGap) {
  for (const auto& [n, seed] : {std::pair{12, 1}, std::pair{12, 2}, std::pair{8, 3}}) {
    const FlowResult r = run_counterflow(n, static_cast<std::uint64_t>(seed), 900.0, {});
    EXPECT_EQ(r.collisions, 0);
    EXPECT_EQ(r.arrived, r.agents) << n << " per team, seed " << seed;
    EXPECT_LT(r.max_time_ratio, 3.0) << n << " per team, seed " << seed;
  }
}

// A corridor one figure wide (1 m: 0.5 m walkable) and 4 m long: the
// streams can only take turns. Without the passage rules none of the 12
// arrives.
TEST(CrowdCounterflow, StreamsTakeTurnsInACorridorOneFigureWide) {
  const FlowResult r = run_counterflow(6, 5, 900.0, {}, corridor_world(1.0));
  EXPECT_EQ(r.collisions, 0);
  EXPECT_EQ(r.arrived, r.agents);
}

// Within three times the straight-line time: the figures of the way that
// has the corridor queue at its mouth and go in one at a time (before:
// 4.0, four of them pressing into the mouth at once locked there for two
// minutes).
TEST(CrowdCounterflow, GoalCorridorWithinThreeTimes) {
  EXPECT_LT(run_counterflow(6, 5, 900.0, {}, corridor_world(1.0)).max_time_ratio, 3.0);
}

// The passage in a wall with one 2 m gap: found, across the wall.
TEST(CrowdCounterflow, FindsTheGapAsAPassage) {
  const NavWorldConfig w = one_gap_world(2.0);
  const auto found = find_passages(w.walls, 2.3);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].centre.x, 0.0, 1e-9);
  EXPECT_NEAR(found[0].centre.y, 0.0, 1e-9);
  EXPECT_NEAR(found[0].half_width, 1.0, 1e-9);
  EXPECT_NEAR(std::abs(found[0].axis.x), 1.0, 1e-9);
  EXPECT_TRUE(find_passages(one_gap_world(3.5).walls, 2.3).empty());
}

// The way that waits stands beside its mouth, near the wall's face and
// well to the side, where its crowd keeps clear of the way in to the mouth
// and of the way out. Where a wall stands across that place, it waits at
// the first place nearer the passage's axis (0.5 m at a time) that a
// figure can stand on in sight of the mouth.
TEST(CrowdCounterflow, TheWaitingPlaceMovesOutOfAWallAcrossIt) {
  const NavWorldConfig open = one_gap_world(2.0);
  NavWorldConfig walled = open;
  // East of the gap, square to its wall, 1 m thick across where the blue
  // team waits (4 m aside of the gap's edge): 4.5-5.5 m north of the axis.
  walled.walls.push_back({{2.05, 1.0 + PassageParams{}.wait_aside_m}, {4.1, 1.0}, 0.0});
  std::vector<Agent> agents(2);
  agents[0].position = {-1.5, 0.0};  // red, nearer its mouth: its way has the gap
  agents[1].position = {3.5, 0.0};   // blue, waits
  for (Agent& a : agents) a.radius = 0.25;
  const std::vector<Vec2> targets{{9, 0}, {-9, 0}};
  const PassageParams params;
  const double r = 0.35;  // the avoidance radius
  for (const NavWorldConfig* config : {&open, static_cast<const NavWorldConfig*>(&walled)}) {
    NavWorld world(*config);
    PassageRules rules(config->walls, r, params, &world);
    ASSERT_EQ(rules.passages().size(), 1u);
    rules.update(0.0, agents, targets, std::vector<bool>(2, true));
    ASSERT_FALSE(rules.held(0));
    ASSERT_TRUE(rules.held(1));
    const Vec2 at = rules.hold_point(1);
    // Out from the east mouth (the wall's face at x = 0.25), on blue's right.
    EXPECT_NEAR(at.x, 0.25 + params.wait_back_m + r, 1e-9);
    if (config == &open) {
      EXPECT_NEAR(at.y, 1.0 + params.wait_aside_m, 1e-9);
    } else {
      // 3.5 m aside lies in the wall's reach (within a figure's radius of
      // it); 3 m aside, 0.25 m clear of that, is the first place free.
      EXPECT_NEAR(at.y, 1.0 + params.wait_aside_m - 1.0, 1e-9);
      EXPECT_TRUE(world.on_mesh(at, 0.05));
      EXPECT_FALSE(world.in_wall(at, 0.25));
    }
  }
}

// A gap near the scene's edge (its upper wall part 1 m long): no place
// beside the mouth on that side has room, so the way whose right side it
// is waits on its left, 4 m aside of the gap's other edge, instead of at
// the mesh's edge beside the mouth (where its crowd stood round the
// mouth: teams of 25 home on 4 of 20 seeds, 12 with this).
TEST(CrowdCounterflow, AWayWithNoRoomOnItsRightWaitsOnItsLeft) {
  NavWorldConfig c;
  c.bounds = {-14, -7, 14, 7};
  c.walls = {{{0, -1.5}, {0.5, 11}, 0.0}, {{0, 6.5}, {0.5, 1}, 0.0}};  // the gap at y 4..6
  c.agent_radius_m = 0.25;
  NavWorld world(c);
  std::vector<Agent> agents(2);
  agents[0].position = {-1.5, 5.0};  // red, nearer its mouth: its way has the gap
  agents[1].position = {3.5, 5.0};   // blue, waits; its right is north, toward the edge
  for (Agent& a : agents) a.radius = 0.25;
  const std::vector<Vec2> targets{{9, 0}, {-9, 0}};
  const PassageParams params;
  PassageRules rules(c.walls, 0.35, params, &world);
  ASSERT_EQ(rules.passages().size(), 1u);
  rules.update(0.0, agents, targets, std::vector<bool>(2, true));
  ASSERT_FALSE(rules.held(0));
  ASSERT_TRUE(rules.held(1));
  const Vec2 at = rules.hold_point(1);
  EXPECT_NEAR(at.x, 0.25 + params.wait_back_m + 0.35, 1e-9);
  EXPECT_NEAR(at.y, 4.0 - params.wait_aside_m, 1e-9);
}

}  // namespace
}  // namespace animrt::herd
