#include "animrt/controllers/herd/wander_leader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace animrt::herd {
namespace {

WanderParams params() {
  WanderParams p;
  p.speed = 0.1;
  p.turn_gain = 1.0;
  p.wander_m = {2.0, -1.0, 6.0, 1.0};
  p.reach_m = 0.3;
  return p;
}

TEST(WanderLeader, GoalsAreUniformInsideTheRectangle) {
  WanderParams p = params();
  p.speed = 0.0;
  p.reach_m = 1e9;  // every step reaches the goal, so every step draws one
  WanderLeader w(p, {0, 0}, 0.0, 11);
  int quadrant[4] = {0, 0, 0, 0};
  Vec2 mean;
  const int n = 4000;
  for (int k = 0; k < n; ++k) {
    w.step(0.1);
    const Vec2 g = w.goal();
    ASSERT_TRUE(p.wander_m.contains(g)) << g.x << " " << g.y;
    mean += g / n;
    ++quadrant[(g.x > 4.0 ? 1 : 0) + (g.y > 0.0 ? 2 : 0)];
  }
  EXPECT_EQ(w.goals_drawn(), n + 1);
  EXPECT_NEAR(mean.x, 4.0, 0.1);
  EXPECT_NEAR(mean.y, 0.0, 0.05);
  for (const int q : quadrant) EXPECT_NEAR(q, n / 4, n / 20);
}

TEST(WanderLeader, TurnsByTheGainTimesDtFractionOfTheAngle) {
  WanderParams p = params();
  p.wander_m = {0.0, 10.0, 0.0, 10.0};  // the goal is (0, 10)
  WanderLeader w(p, {0, 0}, 0.0, 1);
  w.step(0.1);
  // After moving to (0.01, 0) the bearing is atan2(10, -0.01).
  const double bearing = std::atan2(10.0, -0.01);
  EXPECT_NEAR(w.heading(), 0.1 * bearing, 1e-12);
  EXPECT_NEAR(w.position().x, 0.01, 1e-12);

  p.max_turn = 0.05;
  WanderLeader capped(p, {0, 0}, 0.0, 1);
  capped.step(0.1);
  EXPECT_NEAR(capped.heading(), 0.005, 1e-12);
}

TEST(WanderLeader, ReachesGoalsAndStaysNearTheRectangle) {
  WanderLeader w(params(), {4.0, 0.0}, 0.0, 5);
  for (int k = 0; k < 20000; ++k) {
    w.step(0.1);
    const Rect r = params().wander_m;
    ASSERT_TRUE((Rect{r.xmin - 1, r.ymin - 1, r.xmax + 1, r.ymax + 1}.contains(w.position())));
  }
  EXPECT_GT(w.goals_drawn(), 20);
}

TEST(WanderLeader, DrawsANewGoalExactlyWhenWithinReach) {
  WanderLeader w(params(), {4.0, 0.0}, 0.0, 21);
  for (int k = 0; k < 5000; ++k) {
    const Vec2 goal = w.goal();
    const int drawn = w.goals_drawn();
    w.step(0.1);
    const bool reached = norm(goal - w.position()) <= params().reach_m;
    ASSERT_EQ(w.goals_drawn(), drawn + (reached ? 1 : 0)) << "step " << k;
    if (!reached) {
      ASSERT_EQ(w.goal(), goal);
    }
  }
}

TEST(WanderLeader, IsDeterministicForASeed) {
  WanderLeader a(params(), {0, 0}, 0.0, 9), b(params(), {0, 0}, 0.0, 9),
      c(params(), {0, 0}, 0.0, 10);
  for (int k = 0; k < 3000; ++k) {
    a.step(0.1);
    b.step(0.1);
    c.step(0.1);
  }
  EXPECT_EQ(a.position(), b.position());
  EXPECT_EQ(a.goal(), b.goal());
  EXPECT_NE(a.goal(), c.goal());
}

TEST(WanderLeader, RejectsBadParameters) {
  WanderParams p = params();
  p.wander_m = {1, 0, 0, 1};
  EXPECT_THROW(WanderLeader(p, {}, 0, 1), std::invalid_argument);
  p = params();
  p.speed = -1;
  EXPECT_THROW(WanderLeader(p, {}, 0, 1), std::invalid_argument);
  p = params();
  p.wander_m.xmax = NAN;
  EXPECT_THROW(WanderLeader(p, {}, 0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace animrt::herd
