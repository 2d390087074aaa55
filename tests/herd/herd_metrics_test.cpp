// The herd's metrics on hand-placed agents.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

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
    a.sample(t, aligned.agents, aligned.leaders, aligned.arrived, aligned.max_speed);
    b.sample(t, opposed.agents, opposed.leaders, opposed.arrived, opposed.max_speed);
  }
  EXPECT_NEAR(a.finish().groups[0].order_mean, 1.0, 1e-12);
  EXPECT_NEAR(b.finish().groups[0].order_mean, 0.0, 1e-12);
  EXPECT_NEAR(b.finish().groups[0].order_min, 0.0, 1e-12);
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

}  // namespace
}  // namespace animrt::herd
