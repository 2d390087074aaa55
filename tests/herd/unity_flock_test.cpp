#include "animrt/controllers/herd/unity_flock.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
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

// Every force zero, no minimum speed, turning free: a test turns on the rule
// it checks.
UnityFlockParams no_rules() {
  UnityFlockParams p;
  p.min_speed = 0.0;
  p.turn_speed = 1000.0;
  p.random_freq = 1.0;
  p.random_force = 0.0;
  p.to_origin_force = 0.0;
  p.to_origin_range = 1.0;
  p.gravity = 0.0;
  p.avoidance_radius = 1.0;
  p.avoidance_force = 0.0;
  p.follow_velocity = 0.0;
  p.follow_radius = 2.0;
  return p;
}

TEST(UnityFlock, SeparationPushesApartAcrossGroupsInsideTheRadius) {
  UnityFlockParams p = no_rules();
  p.avoidance_force = 2.0;
  std::vector<Agent> a{agent({0, 0}), agent({0.5, 0}), agent({0, 0.75}, 0, 0, 1)};
  std::vector<Vec2> d(3);
  UnityFlock f({0, 1}, p, still_leader({0, 0}), 1);
  f.steer(0, 0.1, a, d);
  // Agent 0: from agent 1, (1 - 0.5) * 2 along -x; from agent 2 (other
  // group), (1 - 0.75) * 2 along -y; over one other member; times dt.
  EXPECT_NEAR(d[0].x, -0.1, 1e-12);
  EXPECT_NEAR(d[0].y, -0.05, 1e-12);
  EXPECT_GT(d[1].x, 0.0);
  // Beyond the avoidance radius nothing pushes (a new flock: this one's
  // boids now have a velocity of their own).
  a[1].position = {1.5, 0};
  a[2].position = {0, -1.2};
  UnityFlock g({0, 1}, p, still_leader({0, 0}), 1);
  g.steer(0, 0.1, a, d);
  EXPECT_EQ(d[0], Vec2{});
}

TEST(UnityFlock, AlignmentFollowsOwnGroupNeighboursOnly) {
  UnityFlockParams p = no_rules();
  p.follow_velocity = 1.0;
  const double pi = std::numbers::pi;
  // Agent 1 (same group) walks +y at 1.5 m; agent 2 (other group) walks -x.
  std::vector<Agent> a{agent({0, 0}), agent({1.5, 0}, pi / 2, 0.1), agent({0, 1}, pi, 0.1, 1)};
  std::vector<Vec2> d(3);
  UnityFlock f({0, 1}, p, still_leader({0, 0}), 1);
  f.steer(0, 0.1, a, d);
  // Unit velocity (0, 1) * d/follow_radius * follow_velocity, one other, dt.
  EXPECT_NEAR(d[0].x, 0.0, 1e-12);
  EXPECT_NEAR(d[0].y, 0.1 * 0.75, 1e-12);
  // A standing neighbour aligns along its heading.
  a[1].speed = 0.0;
  a[1].heading = 0.0;
  UnityFlock f2({0, 1}, p, still_leader({0, 0}), 1);
  f2.steer(0, 0.1, a, d);
  EXPECT_NEAR(d[0].x, 0.075, 1e-12);
  EXPECT_NEAR(d[0].y, 0.0, 1e-12);
  // Behaviour: walking figures with headings apart come to share one.
  p.turn_speed = 0.6;
  p.min_speed = 0.05;
  p.follow_velocity = 0.2;
  std::vector<Agent> b{agent({0, 0}, 0.0, 0.08), agent({0, 1.2}, 1.0, 0.08),
                       agent({1.2, 0}, -0.8, 0.08)};
  std::vector<Vec2> db(3);
  UnityFlock g({0, 1, 2}, p, still_leader({0, 0}), 1);
  const double before = test::order_parameter(b);
  for (int s = 0; s < 300; ++s) {
    g.steer(s * 0.1, 0.1, b, db);
    test::walk(b, db, FigureLimits{}, 0.1);
  }
  EXPECT_LT(before, 0.85);
  EXPECT_GT(test::order_parameter(b), 0.99);
}

TEST(UnityFlock, CohesionPullsTowardTheOthersMeanPosition) {
  UnityFlockParams p = no_rules();
  p.gravity = 0.5;
  std::vector<Agent> a{agent({0, 0}), agent({0, 2}), agent({6, 1}), agent({-20, 0}, 0, 0, 1)};
  std::vector<Vec2> d(4);
  UnityFlock f({0, 1, 2}, p, still_leader({0, 0}), 1);
  f.steer(0, 0.1, a, d);
  // For agent 2 the others' mean is (0, 1): unit (-1, 0) * gravity * dt.
  EXPECT_NEAR(d[2].x, -0.05, 1e-12);
  EXPECT_NEAR(d[2].y, 0.0, 1e-12);
  // Agent 0: toward (3, 1.5).
  EXPECT_NEAR(d[0].y / d[0].x, 0.5, 1e-12);
}

TEST(UnityFlock, OriginPushClosesOnTheLeader) {
  UnityFlockParams p = no_rules();
  p.to_origin_force = 0.05;
  p.turn_speed = 0.6;
  std::vector<Agent> a{agent({0, 0}, 0.0), agent({0, 2}, 2.5)};
  std::vector<Vec2> d(2);
  UnityFlock f({0, 1}, p, still_leader({5, 3}), 1);
  f.steer(0, 0.1, a, d);
  // d/range * force along the way to the leader, times dt, from standing.
  EXPECT_NEAR(d[0].x, 0.1 * 0.05 * 5.0, 1e-12);
  EXPECT_NEAR(d[0].y, 0.1 * 0.05 * 3.0, 1e-12);
  for (int s = 0; s < 1500; ++s) {
    f.steer(s * 0.1, 0.1, a, d);
    test::walk(a, d, FigureLimits{}, 0.1);
  }
  for (const Agent& x : a) EXPECT_LT(norm(x.position - Vec2{5, 3}), 1.0);
}

// The boid keeps its own velocity, as the text's does: while its figure
// stands (its slowest walk is faster than one step's pull), the pull builds
// up step by step until it asks for a walk. Started from the figure's
// walked velocity each step, it asked for one step's pull forever.
TEST(UnityFlock, AStandingFiguresBoidBuildsUpItsVelocity) {
  UnityFlockParams p = no_rules();
  p.to_origin_force = 0.05;
  p.turn_speed = 0.6;
  std::vector<Agent> a{agent({0, 0}, 0.0), agent({0, 5}, 0.0)};
  std::vector<Vec2> d(2);
  UnityFlock f({0, 1}, p, still_leader({2, 0}), 1);
  f.steer(0, 0.1, a, d);
  EXPECT_NEAR(d[0].x, 0.1 * 0.05 * 2.0, 1e-12);              // one step's pull from standing
  for (int s = 1; s < 50; ++s) f.steer(s * 0.1, 0.1, a, d);  // the figures stand
  // v' = F - v: after 5 s, (1 - 0.9^50) of F = 0.05 * 2 m/s.
  EXPECT_NEAR(d[0].x, 0.1 * (1.0 - std::pow(0.9, 50)), 1e-9);
  EXPECT_GT(norm(d[0]), 0.086);  // faster than the pony's slowest walk
}

TEST(UnityFlock, MinSpeedAndTurnLimitHold) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-5, 5);
  UnityFlockParams p = test::pony_unity();
  p.min_speed = 0.05;
  p.random_force = 1.0;
  std::vector<Agent> a;
  for (int i = 0; i < 40; ++i) a.push_back(agent({u(rng), u(rng)}, u(rng), i % 3 ? 0.1 : 0.0));
  std::vector<Vec2> d(a.size());
  UnityFlock f(iota(40), p, still_leader({0, 0}), 1);
  std::vector<Vec2> last(a.size());
  for (int s = 0; s < 20; ++s) {
    f.steer(s * 0.1, 0.1, a, d);
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_GE(norm(d[i]), 0.05 - 1e-12);
      // Turned from the boid's velocity (at the first step the walked
      // direction, the heading when standing) by at most turn_speed * dt.
      const Vec2 from = s == 0 ? heading_vector(a[i].heading) : last[i];
      EXPECT_LE(std::abs(std::atan2(cross(from, d[i]), dot(from, d[i]))), 0.06 + 1e-9);
    }
    last = d;
  }
}

TEST(UnityFlock, RandomPushIsRenewedAtRandomIntervals) {
  UnityFlockParams p = no_rules();
  p.random_force = 1.0;
  p.random_freq = 2.0;  // renewed every 0.25-0.75 s
  std::vector<Agent> a{agent({0, 0}), agent({9, 9})};
  std::vector<Vec2> d(2);
  UnityFlock f({0, 1}, p, still_leader({0, 0}), 1);
  Vec2 last{-1, -1}, velocity;
  int changes = 0, longest = 0, run = 0;
  for (int s = 0; s < 1000; ++s) {
    f.steer(s * 0.01, 0.01, a, d);
    // The boid's velocity decays by dt and takes the push * dt.
    const Vec2 push = d[0] - velocity * (1.0 - 0.01);
    velocity = d[0];
    ASSERT_LE(norm(push), 0.01 + 1e-12);  // a unit-disc point * force * dt
    if (norm(push - last) > 1e-9) {
      ++changes;
      run = 0;
    }
    longest = std::max(longest, ++run);
    last = push;
  }
  EXPECT_GE(changes, 10 / 0.75 - 1);
  EXPECT_LE(changes, 10 / 0.25 + 1);
  EXPECT_LE(longest, 76);
}

TEST(UnityFlock, GridAndAllPairsAgree) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-8, 8);
  std::vector<Agent> a;
  for (int i = 0; i < 400; ++i) a.push_back(agent({u(rng), u(rng)}, u(rng), 0.1 * (i % 4), i % 2));
  std::vector<int> members;
  for (int i = 0; i < 400; i += 2) members.push_back(i);
  const UnityFlockParams p = test::pony_unity();
  UnityFlock grid(members, p, still_leader({1, 1}), 5);
  UnityFlock all(members, p, still_leader({1, 1}), 5);
  all.set_neighbour_search(NeighbourSearch::all_pairs);
  std::vector<Vec2> dg(400), da(400);
  grid.steer(0, 0.1, a, dg);
  all.steer(0, 0.1, a, da);
  for (const int i : members) {
    EXPECT_NEAR(dg[static_cast<std::size_t>(i)].x, da[static_cast<std::size_t>(i)].x, 1e-12);
    EXPECT_NEAR(dg[static_cast<std::size_t>(i)].y, da[static_cast<std::size_t>(i)].y, 1e-12);
  }
  EXPECT_EQ(dg[1], Vec2{});
}

TEST(UnityFlock, IsDeterministicForASeedAndSteersWithoutAllocating) {
  auto run = [&](std::uint64_t seed, long* allocs) {
    std::vector<Agent> a = test::lattice(30, {0, 0}, 0.8, 0.0, 0, 2);
    UnityFlock f(iota(30), test::pony_unity(),
                 WanderLeader(test::pony_leader({0, 0}), {2, 0}, 0, 3), seed);
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

TEST(UnityFlock, RejectsBadParameters) {
  UnityFlockParams p;
  p.to_origin_range = 0.0;
  EXPECT_THROW(UnityFlock({0}, p, still_leader({}), 1), std::invalid_argument);
  p = UnityFlockParams{};
  p.gravity = -1.0;
  EXPECT_THROW(UnityFlock({0}, p, still_leader({}), 1), std::invalid_argument);
  EXPECT_THROW(UnityFlock({1, 1}, UnityFlockParams{}, still_leader({}), 1), std::invalid_argument);
}

TEST(UnityFlock, PonyFlockStaysOrderedWithoutCollisions) {
  for (const unsigned seed : {1u, 2u}) {
    std::vector<Agent> a = test::lattice(30, {0, 0}, 0.8, 0.0, 0, seed);
    UnityFlock f(iota(30), test::pony_unity(),
                 WanderLeader(test::pony_leader({0, 0}), {2, 0}, 0, seed + 100), seed);
    std::vector<Vec2> d(30);
    double min_order = 1.0;
    int collisions = 0;
    for (int s = 0; s < 3600; ++s) {
      f.steer(s * 0.1, 0.1, a, d);
      test::walk(a, d, FigureLimits{}, 0.1);
      collisions += test::collisions(a);
      if (s >= 600) min_order = std::min(min_order, test::order_parameter(a));
    }
    EXPECT_EQ(collisions, 0) << "seed " << seed;
    EXPECT_GE(min_order, 0.9) << "seed " << seed;
  }
}

}  // namespace
}  // namespace animrt::herd
