#include "animrt/controllers/herd/reynolds_flock.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "herd/figure_sim.hpp"
#include "herd/pony_params.hpp"
#include "support/alloc_counter.hpp"

namespace animrt::herd {
namespace {

using test::agent;
using test::FigureLimits;
using test::iota;
using test::still_leader;

// Every rule weighted zero, speeds free: a test turns on the rule it checks.
ReynoldsFlockParams none() {
  ReynoldsFlockParams p;
  p.min_velocity = 0.0;
  p.max_velocity = 100.0;
  p.center_weight = p.velocity_weight = p.separation_weight = p.follow_weight = p.randomize_weight =
      0.0;
  p.separation_radius = 3.0;
  return p;
}

TEST(ReynoldsFlock, SeparationPushesApartAcrossGroups) {
  ReynoldsFlockParams p = none();
  p.separation_weight = 1.0;
  // Agents 0 and 1 are the flock; agent 2 belongs to another group.
  std::vector<Agent> a{agent({0, 0}), agent({1, 0}), agent({0.5, 1.0}, 0, 0, 1)};
  std::vector<Vec2> d(3);
  ReynoldsFlock f({0, 1}, p, still_leader({0, 0}), 1);
  f.steer(0, 0.1, a, d);
  EXPECT_LT(d[0].x, 0.0);
  EXPECT_GT(d[1].x, 0.0);
  EXPECT_LT(d[0].y, 0.0);  // the other group's agent pushes too
  EXPECT_LT(d[1].y, 0.0);
  // sum r/|r|^2: from agent 1, (-1, 0); from agent 2, (-0.5, -1)/1.25; times dt.
  EXPECT_NEAR(d[0].x, 0.1 * (-1.0 - 0.4), 1e-12);
  EXPECT_NEAR(d[0].y, 0.1 * -0.8, 1e-12);
  // Outside the cutoff nothing pushes.
  a[1].position = {3.5, 0};
  a[2].position = {-3.5, 0};
  f.steer(0, 0.1, a, d);
  EXPECT_EQ(d[0], Vec2{});  // zero steer keeps the (zero) walked velocity
}

TEST(ReynoldsFlock, AlignmentTurnsTowardTheFlocksVelocityOnly) {
  ReynoldsFlockParams p = none();
  p.velocity_weight = 1.0;
  const double pi = std::numbers::pi;
  std::vector<Agent> a{agent({0, 0}, 0, 1), agent({0, 1}, 0, 1), agent({5, 0}, pi / 2, 1),
                       agent({5, 1}, pi, 1, 1)};
  std::vector<Vec2> d(4);
  ReynoldsFlock f({0, 1, 2}, p, still_leader({0, 0}), 1);
  f.steer(0, 0.1, a, d);
  // Mean of the three members' velocities: (2/3, 1/3); agent 2 moves +y and
  // is steered by (mean - v) * dt, turning it right toward +x.
  EXPECT_NEAR(d[2].x, 0.1 * 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(d[2].y, 0.1 * (1.0 / 3.0 - 1.0), 1e-12);
  EXPECT_LT(cross(a[2].velocity(), d[2]), 0.0);
  // Behaviour over time: with follow off, alignment brings headings together.
  p.velocity_weight = 10.0;  // = 1/dt: the desired velocity is the deviation itself
  p.follow_weight = 0.0;
  p.min_velocity = 0.05;
  p.max_velocity = 0.1;
  std::vector<Agent> b{agent({0, 0}, 0.0, 0.1), agent({0, 3}, 1.2, 0.1), agent({3, 0}, -0.9, 0.1)};
  std::vector<Vec2> db(3);
  ReynoldsFlock g({0, 1, 2}, p, still_leader({0, 0}), 1);
  const double before = test::order_parameter(b);
  for (int s = 0; s < 300; ++s) {
    g.steer(s * 0.1, 0.1, b, db);
    test::walk(b, db, FigureLimits{}, 0.1);
  }
  EXPECT_LT(before, 0.8);
  EXPECT_GT(test::order_parameter(b), 0.99);
}

TEST(ReynoldsFlock, CohesionPullsTowardTheFlockCentre) {
  ReynoldsFlockParams p = none();
  p.center_weight = 1.0;
  std::vector<Agent> a{agent({0, 0}), agent({0, 2}), agent({6, 1}), agent({-20, 0}, 0, 0, 1)};
  std::vector<Vec2> d(4);
  ReynoldsFlock f({0, 1, 2}, p, still_leader({0, 0}), 1);
  f.steer(0, 0.1, a, d);
  // Centre of the members (2, 1); the other group's agent does not count.
  EXPECT_NEAR(d[2].x, 0.1 * (2.0 - 6.0), 1e-12);
  EXPECT_NEAR(d[2].y, 0.0, 1e-12);
  EXPECT_GT(d[0].x, 0.0);
  EXPECT_GT(d[0].y, 0.0);
}

TEST(ReynoldsFlock, FollowClosesOnTheLeader) {
  ReynoldsFlockParams p = none();
  p.follow_weight = 0.5;
  p.max_velocity = 0.12;
  std::vector<Agent> a{agent({0, 0}, 0.0), agent({0, 2}, 2.0)};
  std::vector<Vec2> d(2);
  ReynoldsFlock f({0, 1}, p, still_leader({6, 4}), 1);
  for (int s = 0; s < 1200; ++s) {
    f.steer(s * 0.1, 0.1, a, d);
    test::walk(a, d, FigureLimits{}, 0.1);
  }
  for (const Agent& x : a) EXPECT_LT(norm(x.position - Vec2{6, 4}), 0.3);
}

TEST(ReynoldsFlock, SpeedLimitsHold) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-5, 5);
  ReynoldsFlockParams p;  // the text's weights
  p.min_velocity = 0.05;
  p.max_velocity = 0.12;
  std::vector<Agent> a;
  for (int i = 0; i < 40; ++i) a.push_back(agent({u(rng), u(rng)}, u(rng), i % 3 ? 0.1 : 0.0));
  std::vector<Vec2> d(a.size());
  ReynoldsFlock f(iota(40), p, still_leader({0, 0}), 1);
  for (const double dt : {0.001, 0.1, 5.0}) {
    f.steer(0, dt, a, d);
    for (const Vec2 v : d) {
      EXPECT_GE(norm(v), 0.05 - 1e-12);
      EXPECT_LE(norm(v), 0.12 + 1e-12);
    }
  }
  // A standing figure with nothing to steer it walks off along its heading.
  ReynoldsFlockParams q = none();
  q.min_velocity = 0.05;
  std::vector<Agent> one{agent({0, 0}, 1.0)};
  std::vector<Vec2> d1(1);
  ReynoldsFlock g({0}, q, still_leader({0, 0}), 1);
  g.steer(0, 0.1, one, d1);
  EXPECT_NEAR(d1[0].x, 0.05 * std::cos(1.0), 1e-12);
  EXPECT_NEAR(d1[0].y, 0.05 * std::sin(1.0), 1e-12);
}

TEST(ReynoldsFlock, RandomizeIsAUnitVectorTimesWeight) {
  ReynoldsFlockParams p = none();
  p.randomize_weight = 2.0;
  std::vector<Agent> a{agent({0, 0}), agent({9, 9})};
  std::vector<Vec2> d(2);
  ReynoldsFlock f({0, 1}, p, still_leader({0, 0}), 1);
  Vec2 mean;
  for (int s = 0; s < 500; ++s) {
    f.steer(s * 0.1, 0.1, a, d);
    EXPECT_NEAR(norm(d[0]), 0.2, 1e-12);
    mean += d[0] / 500.0;
  }
  EXPECT_LT(norm(mean), 0.03);  // no preferred direction
}

std::vector<Agent> random_herd(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-8, 8);
  std::vector<Agent> a;
  for (int i = 0; i < n; ++i) a.push_back(agent({u(rng), u(rng)}, u(rng), 0.1 * (i % 4), i % 2));
  return a;
}

TEST(ReynoldsFlock, GridAndAllPairsAgree) {
  const std::vector<Agent> a = random_herd(400, 3);
  std::vector<int> members;
  for (int i = 0; i < 400; i += 2) members.push_back(i);
  ReynoldsFlockParams p = none();
  p.separation_weight = 1.0;
  p.center_weight = 0.1;
  p.follow_weight = 0.2;
  p.separation_radius = 1.5;
  ReynoldsFlock grid(members, p, still_leader({1, 1}), 5);
  ReynoldsFlock all(members, p, still_leader({1, 1}), 5);
  all.set_neighbour_search(NeighbourSearch::all_pairs);
  std::vector<Vec2> dg(400), da(400);
  grid.steer(0, 0.1, a, dg);
  all.steer(0, 0.1, a, da);
  for (const int i : members) {
    EXPECT_NEAR(dg[static_cast<std::size_t>(i)].x, da[static_cast<std::size_t>(i)].x, 1e-12);
    EXPECT_NEAR(dg[static_cast<std::size_t>(i)].y, da[static_cast<std::size_t>(i)].y, 1e-12);
  }
  EXPECT_EQ(dg[1], Vec2{});  // other groups' entries are left alone
}

TEST(ReynoldsFlock, IsDeterministicForASeedAndSteersWithoutAllocating) {
  const ReynoldsFlockParams p = test::pony_reynolds();
  auto run = [&](std::uint64_t seed, long* allocs) {
    std::vector<Agent> a = test::lattice(30, {0, 0}, 0.8, 0.0, 0, 2);
    ReynoldsFlock f(iota(30), p, WanderLeader(test::pony_leader({0, 0}), {2, 0}, 0, 3), seed);
    std::vector<Vec2> d(30);
    f.steer(0, 0.1, a, d);
    animrt::test::AllocationCounter c;
    for (int s = 1; s < 200; ++s) {
      f.steer(s * 0.1, 0.1, a, d);
      test::walk(a, d, FigureLimits{}, 0.1);
    }
    if (allocs) *allocs = c.count();
    return a;
  };
  long allocs = -1;
  const std::vector<Agent> a = run(7, &allocs), b = run(7, nullptr), c = run(8, nullptr);
  EXPECT_EQ(allocs, 0);
  bool differs = false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].position, b[i].position);
    differs = differs || !(a[i].position == c[i].position);
  }
  EXPECT_TRUE(differs);
}

TEST(ReynoldsFlock, RejectsBadParametersAndMembers) {
  ReynoldsFlockParams p;
  p.min_velocity = 9.0;
  EXPECT_THROW(ReynoldsFlock({0}, p, still_leader({}), 1), std::invalid_argument);
  p = ReynoldsFlockParams{};
  p.separation_radius = NAN;
  EXPECT_THROW(ReynoldsFlock({0}, p, still_leader({}), 1), std::invalid_argument);
  EXPECT_THROW(ReynoldsFlock({0, 0}, ReynoldsFlockParams{}, still_leader({}), 1),
               std::invalid_argument);
  EXPECT_THROW(ReynoldsFlock({-1}, ReynoldsFlockParams{}, still_leader({}), 1),
               std::invalid_argument);
  ReynoldsFlock f({0, 5}, ReynoldsFlockParams{}, still_leader({}), 1);
  std::vector<Agent> a(3);
  std::vector<Vec2> d(3);
  EXPECT_THROW(f.steer(0, 0.1, a, d), std::invalid_argument);
}

// The goal for walking figures: 30 ponies following their wandering leader
// stay ordered and never touch.
TEST(ReynoldsFlock, PonyFlockStaysOrderedWithoutCollisions) {
  for (const unsigned seed : {1u, 2u, 3u}) {
    std::vector<Agent> a = test::lattice(30, {0, 0}, 0.8, 0.0, 0, seed);
    ReynoldsFlock f(iota(30), test::pony_reynolds(),
                    WanderLeader(test::pony_leader({0, 0}), {2, 0}, 0, seed + 100), seed);
    std::vector<Vec2> d(30);
    double min_order = 1.0;
    int collisions = 0;
    double lead_dist = 0;
    for (int s = 0; s < 3600; ++s) {
      f.steer(s * 0.1, 0.1, a, d);
      test::walk(a, d, FigureLimits{}, 0.1);
      collisions += test::collisions(a);
      if (s >= 600) {  // formed after 60 s
        min_order = std::min(min_order, test::order_parameter(a));
        Vec2 c;
        for (const Agent& x : a) c += x.position / 30.0;
        lead_dist = std::max(lead_dist, norm(c - f.leader().position()));
      }
    }
    EXPECT_EQ(collisions, 0) << "seed " << seed;
    EXPECT_GE(min_order, 0.9) << "seed " << seed;
    EXPECT_LT(lead_dist, 5.0) << "seed " << seed;  // it does follow
    EXPECT_GT(f.leader().goals_drawn(), 2);
  }
}

}  // namespace
}  // namespace animrt::herd
