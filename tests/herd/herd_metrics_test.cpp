// The herd's metrics on hand-placed agents.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "animrt/controllers/herd/herd_output.hpp"
#include "animrt/controllers/herd/metrics.hpp"

namespace animrt::herd {
namespace {

Agent at(double x, double y, double heading, double speed, int group = 0) {
  Agent a;
  a.position = {x, y};
  a.heading = heading;
  a.speed = speed;
  a.radius = 0.25;
  a.group = group;
  return a;
}

struct Fixture {
  std::vector<Agent> agents;
  std::vector<std::optional<Vec2>> leaders;
  std::vector<char> arrived;
  std::vector<double> max_speed;
  Fixture(std::vector<Agent> a, int groups)
      : agents(std::move(a)),
        leaders(static_cast<std::size_t>(groups)),
        arrived(agents.size(), 0),
        max_speed(agents.size(), 0.1) {}
};

// Each figure walks what its speed and heading say for dt: the metrics
// read a figure's motion from its positions.
void walk(std::vector<Agent>& agents, double dt) {
  for (Agent& a : agents) a.position += a.velocity() * dt;
}

std::vector<GroupInfo> one_group(int n, std::optional<Vec2> target = {}) {
  GroupInfo g{"g", "crowd", {}, target};
  for (int i = 0; i < n; ++i) g.members.push_back(i);
  return {g};
}

TEST(HerdMetrics, CountsPairsCloserThanTheirRadii) {
  Fixture f({at(0, 0, 0, 0.1), at(0.4, 0, 0, 0.1), at(5, 0, 0, 0.1), at(5.6, 0, 0, 0.1)}, 1);
  MetricsRecorder r(one_group(4), f.agents, 0.0);
  r.sample(0.0, f.agents, f.leaders, f.arrived, f.max_speed);
  r.sample(0.1, f.agents, f.leaders, f.arrived, f.max_speed);
  const HerdMetrics m = r.finish();
  EXPECT_EQ(m.collisions, 2);  // one pair (0.4 < 0.5) at each of two steps; 0.6 apart is clear
  EXPECT_NEAR(m.min_pair_distance_m, 0.4, 1e-12);
  EXPECT_NEAR(m.min_clearance_m, -0.1, 1e-12);
  EXPECT_EQ(m.groups[0].collisions, 2);
}

TEST(HerdMetrics, CollisionsAcrossGroupsCountForBoth) {
  Fixture f({at(0, 0, 0, 0.1, 0), at(0.3, 0, 0, 0.1, 1)}, 2);
  MetricsRecorder r({GroupInfo{"a", "unity", {0}, {}}, GroupInfo{"b", "crowd", {1}, Vec2{9, 9}}},
                    f.agents, 0.0);
  r.sample(0.0, f.agents, f.leaders, f.arrived, f.max_speed);
  const HerdMetrics m = r.finish();
  EXPECT_EQ(m.collisions, 1);
  EXPECT_EQ(m.groups[0].collisions, 1);
  EXPECT_EQ(m.groups[1].collisions, 1);
}

TEST(HerdMetrics, CollisionSweepEqualsAllPairs) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  std::vector<Agent> agents;
  for (int i = 0; i < 300; ++i) agents.push_back(at(u(rng), u(rng), 0, 0.1));
  long expected = 0;
  double min_d = 1e9;
  for (std::size_t i = 0; i < agents.size(); ++i) {
    for (std::size_t j = i + 1; j < agents.size(); ++j) {
      const double d = norm(agents[i].position - agents[j].position);
      if (d < 0.5) ++expected;
      min_d = std::min(min_d, d);
    }
  }
  Fixture f(agents, 1);
  MetricsRecorder r(one_group(300), f.agents, 0.0);
  r.sample(0.0, f.agents, f.leaders, f.arrived, f.max_speed);
  const HerdMetrics m = r.finish();
  EXPECT_EQ(m.collisions, expected);
  EXPECT_NEAR(m.min_pair_distance_m, min_d, 1e-12);
}

TEST(HerdMetrics, OrderParameterAfterSettling) {
  Fixture aligned({at(0, 0, 0.1, 0.1), at(2, 0, 0.1, 0.1), at(4, 0, 0.1, 0.1)}, 1);
  Fixture opposed({at(0, 0, 0, 0.1), at(2, 0, M_PI, 0.1)}, 1);
  MetricsRecorder a(one_group(3), aligned.agents, 1.0);
  MetricsRecorder b(one_group(2), opposed.agents, 1.0);
  for (double t : {0.0, 0.5, 1.0, 1.5}) {
    walk(aligned.agents, 0.5);
    walk(opposed.agents, 0.5);
    a.sample(t + 0.5, aligned.agents, aligned.leaders, aligned.arrived, aligned.max_speed);
    b.sample(t + 0.5, opposed.agents, opposed.leaders, opposed.arrived, opposed.max_speed);
  }
  EXPECT_NEAR(a.finish().groups[0].order_mean, 1.0, 1e-12);
  EXPECT_NEAR(b.finish().groups[0].order_mean, 0.0, 1e-12);
  EXPECT_NEAR(b.finish().groups[0].order_min, 0.0, 1e-12);
}

// A flock of 6 all facing one way, its leader walking 0.11 m/s along x for
// 20 s; the flock walks at `speed`.
GroupMetrics flock_behind_walking_leader(double speed) {
  std::vector<Agent> agents;
  for (int i = 0; i < 6; ++i) agents.push_back(at(i, 0, 0.0, speed));
  Fixture f(agents, 1);
  f.max_speed.assign(agents.size(), 0.12);
  GroupInfo g{"f", "unity", {0, 1, 2, 3, 4, 5}, {}};
  MetricsRecorder r({g}, f.agents, 2.0);
  for (int k = 0; k <= 200; ++k) {
    const double t = 0.1 * k;
    f.leaders[0] = Vec2{10 + 0.11 * t, 0};
    for (Agent& a : f.agents) a.position.x += speed * 0.1;
    r.sample(t, f.agents, f.leaders, f.arrived, f.max_speed);
  }
  return r.finish().groups[0];
}

TEST(HerdMetrics, AFlockThatStandsWhileItsLeaderWalksIsStandingNotOrdered) {
  // All facing one way at 0.004 m/s: |sum v| / sum |v| is 1, yet nobody walks.
  const GroupMetrics g = flock_behind_walking_leader(0.004);
  EXPECT_TRUE(g.standing);
  EXPECT_EQ(g.order_steps, 0);  // under a tenth of its top speed, no figure counts as moving
  EXPECT_NEAR(g.speed_mean_mps, 0.004, 1e-9);
  EXPECT_NEAR(g.leader_speed_mean_mps, 0.11, 1e-9);
  EXPECT_EQ(format_order(g), "standing");
  HerdMetrics m;
  m.groups.push_back(g);
  const std::string text = format_metrics(m);
  EXPECT_NE(text.find("standing"), std::string::npos) << text;
  EXPECT_EQ(text.find("order"), std::string::npos) << text;
}

// Figures whose gaits walk 0.1 m/s into a wall that holds them where they
// are: the speed they were asked is no motion. They stand, and have no
// order, while their leader walks on.
TEST(HerdMetrics, AFlockPressedAgainstAWallIsStanding) {
  std::vector<Agent> agents;
  for (int i = 0; i < 6; ++i) agents.push_back(at(0, i, 0.0, 0.1));
  Fixture f(agents, 1);
  f.max_speed.assign(agents.size(), 0.12);
  MetricsRecorder r({GroupInfo{"f", "unity", {0, 1, 2, 3, 4, 5}, {}}}, f.agents, 2.0);
  for (int k = 1; k <= 200; ++k) {
    const double t = 0.1 * k;
    f.leaders[0] = Vec2{10 + 0.11 * t, 0};
    r.sample(t, f.agents, f.leaders, f.arrived, f.max_speed);
  }
  const GroupMetrics g = r.finish().groups[0];
  EXPECT_TRUE(g.standing);
  EXPECT_EQ(g.order_steps, 0);
  EXPECT_EQ(g.speed_mean_mps, 0.0);
}

TEST(HerdMetrics, TheSummaryCountsKnots) {
  HerdMetrics m;
  m.knots = 3;
  const std::string text = format_metrics(m);
  EXPECT_NE(text.find(", 3 knots"), std::string::npos) << text;
}

TEST(HerdMetrics, AFlockWalkingWithItsLeaderIsOrdered) {
  const GroupMetrics g = flock_behind_walking_leader(0.1);
  EXPECT_FALSE(g.standing);
  EXPECT_GT(g.order_steps, 0);
  EXPECT_NEAR(g.order_mean, 1.0, 1e-12);
  EXPECT_NEAR(g.speed_mean_mps, 0.1, 1e-9);
  EXPECT_NEAR(g.leader_speed_mean_mps, 0.11, 1e-9);
  EXPECT_EQ(format_order(g), "order 1.000 mean / 1.000 min");
}

TEST(HerdMetrics, OrderCountsOnlyMovingFigures) {
  // Two walk east; two stand (0.001 m/s, top speed 0.1) facing west: they
  // have no direction to disagree with.
  Fixture f({at(0, 0, 0, 0.1), at(2, 0, 0, 0.1), at(4, 0, M_PI, 0.001), at(6, 0, M_PI, 0.001)}, 1);
  MetricsRecorder r(one_group(4), f.agents, 0.0);
  walk(f.agents, 0.1);
  r.sample(0.1, f.agents, f.leaders, f.arrived, f.max_speed);
  const GroupMetrics g = r.finish().groups[0];
  EXPECT_EQ(g.order_steps, 1);
  EXPECT_NEAR(g.order_mean, 1.0, 1e-12);
}

TEST(HerdMetrics, NearestNeighbourWithinTheGroupOnly) {
  // Agent 2 (other group) sits closest to agent 0 but does not count.
  Fixture f({at(0, 0, 0, 0.1, 0), at(3, 0, 0, 0.1, 0), at(0.1, 2, 0, 0.1, 1)}, 2);
  MetricsRecorder r({GroupInfo{"a", "unity", {0, 1}, {}}, GroupInfo{"b", "unity", {2}, {}}},
                    f.agents, 0.0);
  r.sample(0.0, f.agents, f.leaders, f.arrived, f.max_speed);
  EXPECT_NEAR(r.finish().groups[0].nearest_neighbour_mean_m, 3.0, 1e-12);
}

TEST(HerdMetrics, LeaderDistanceFromTheCentre) {
  Fixture f({at(0, 0, 0, 0.1), at(2, 0, 0, 0.1)}, 1);
  f.leaders[0] = Vec2{1, 3};
  MetricsRecorder r(one_group(2), f.agents, 0.0);
  r.sample(0.0, f.agents, f.leaders, f.arrived, f.max_speed);
  EXPECT_NEAR(r.finish().groups[0].leader_distance_mean_m, 3.0, 1e-12);
}

TEST(HerdMetrics, ArrivalTimesPathsAndStuckFigures) {
  // Agent 0 walks 10 m straight to its target at 1 m/s; agent 1 never moves.
  Fixture f({at(0, 0, 0, 1.0), at(0, 5, 0, 0.0)}, 1);
  f.max_speed = {1.0, 1.0};
  MetricsRecorder r(one_group(2, Vec2{10, 0}), f.agents, 0.0);
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.1 * k;
    f.agents[0].position = {t, 0};
    f.arrived[0] = t >= 10.0 - 1e-9 ? 1 : 0;
    r.sample(t, f.agents, f.leaders, f.arrived, f.max_speed);
  }
  const GroupMetrics g = r.finish().groups[0];
  EXPECT_EQ(g.arrivals, 1);
  EXPECT_NEAR(g.time_to_goal_max_s, 10.0, 1e-9);
  EXPECT_NEAR(g.time_ratio_max, 1.0, 1e-9);
  EXPECT_NEAR(g.path_ratio_mean, 1.0, 1e-9);
  EXPECT_EQ(g.stuck, 1);  // agent 1: still for more than 5 s
}

TEST(HerdMetrics, OneFigureHasNoPairDistanceNorNeighbour) {
  Fixture f({at(0, 0, 0, 0.1)}, 1);
  MetricsRecorder r(one_group(1), f.agents, 0.0);
  walk(f.agents, 0.1);
  r.sample(0.1, f.agents, f.leaders, f.arrived, f.max_speed);
  const HerdMetrics m = r.finish();
  EXPECT_FALSE(m.has_pair);
  EXPECT_FALSE(m.groups[0].has_pair);
  EXPECT_FALSE(m.groups[0].has_neighbour);
  EXPECT_EQ(m.groups[0].order_steps, 0);  // one walking figure has nobody to agree with
  const std::string text = format_metrics(m);
  EXPECT_NE(text.find("min pair distance n/a"), std::string::npos) << text;
  EXPECT_NE(text.find("nearest neighbour n/a"), std::string::npos) << text;
  EXPECT_NE(text.find("order n/a"), std::string::npos) << text;
  EXPECT_EQ(text.find("0.000"), std::string::npos) << text;
}

TEST(HerdMetrics, MinPairDistanceOfFiguresFarApartIsMeasured) {
  Fixture f({at(0, 0, 0, 0.1), at(10, 0, 0, 0.1), at(30, 0, 0, 0.1)}, 1);
  MetricsRecorder r(one_group(3), f.agents, 0.0);
  r.sample(0.0, f.agents, f.leaders, f.arrived, f.max_speed);
  const HerdMetrics m = r.finish();
  EXPECT_TRUE(m.has_pair);
  EXPECT_NEAR(m.min_pair_distance_m, 10.0, 1e-12);
  EXPECT_NEAR(m.min_clearance_m, 9.5, 1e-12);
  EXPECT_EQ(m.collisions, 0);
}

TEST(HerdMetrics, NoArrivalHasNoTimeToGoal) {
  Fixture f({at(0, 0, 0, 0.1), at(3, 0, 0, 0.1)}, 1);
  MetricsRecorder r(one_group(2, Vec2{50, 0}), f.agents, 0.0);
  for (int k = 0; k <= 20; ++k) {
    for (Agent& a : f.agents) a.position.x += 0.01;
    r.sample(0.1 * k, f.agents, f.leaders, f.arrived, f.max_speed);
  }
  HerdMetrics m = r.finish();
  EXPECT_EQ(m.groups[0].arrivals, 0);
  const std::string text = format_metrics(m);
  EXPECT_NE(text.find("arrived 0/2, time to goal n/a, path n/a, stuck 0"), std::string::npos)
      << text;
}

TEST(HerdMetrics, AFigureThatWaitedAndThenArrivedIsNotStuck) {
  // Agent 0 waits 8 s (longer than the 5 s stuck window), then walks 2 m to
  // its target; agent 1 never moves nor arrives.
  Fixture f({at(0, 0, 0, 0.0), at(0, 5, 0, 0.0)}, 1);
  f.max_speed = {1.0, 1.0};
  MetricsRecorder r(one_group(2, Vec2{2, 0}), f.agents, 0.0);
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.1 * k;
    f.agents[0].position = {std::max(0.0, t - 8.0), 0};
    f.arrived[0] = t >= 10.0 - 1e-9 ? 1 : 0;
    r.sample(t, f.agents, f.leaders, f.arrived, f.max_speed);
  }
  const GroupMetrics g = r.finish().groups[0];
  EXPECT_EQ(g.arrivals, 1);
  EXPECT_EQ(g.stuck, 1);  // agent 1 only
}

}  // namespace
}  // namespace animrt::herd
