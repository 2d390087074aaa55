// The navigation world: walls cut the mesh where they stand, paths go
// around them, dropped obstacles carve the mesh and are never dropped onto a
// figure.
#include "animrt/controllers/herd/nav_world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "herd/crowd_sim.hpp"

namespace animrt::herd {
namespace {

NavWorldConfig open_field() {
  NavWorldConfig c;
  c.bounds = {-5, -5, 5, 5};
  c.agent_radius_m = 0.25;
  return c;
}

// A wall across x = 0 with one gap, y in [-1, 1].
NavWorldConfig one_gap() {
  NavWorldConfig c = open_field();
  c.walls = {{{0, -3}, {0.5, 4}, 0.0}, {{0, 3}, {0.5, 4}, 0.0}};
  return c;
}

TEST(NavWorld, WallsAreOffTheMeshAndPathsGoAround) {
  NavWorldConfig c = open_field();
  c.walls = {{{0, 0}, {0.5, 6}, 0.0}};
  NavWorld w(c);
  EXPECT_TRUE(w.on_mesh({-3, 0}));
  EXPECT_TRUE(w.on_mesh({3, 2}));
  EXPECT_FALSE(w.on_mesh({0, 0}));
  EXPECT_FALSE(w.on_mesh({0, 2.9}));
  EXPECT_FALSE(w.on_mesh({0.3, 0}));  // closer to the wall than a figure's radius
  EXPECT_TRUE(w.on_mesh({0.7, 0}));
  EXPECT_FALSE(w.on_mesh({0, 3.1}));  // the wall's end, within a radius
  EXPECT_TRUE(w.on_mesh({0, 3.6}));
  EXPECT_TRUE(w.in_wall({0.1, 1.0}, 0.0));
  EXPECT_TRUE(w.in_wall({0.4, 1.0}, 0.2));
  EXPECT_FALSE(w.in_wall({0.5, 1.0}, 0.2));
  ASSERT_TRUE(w.has_path({-2, 0}, {2, 0}));
  const auto len = w.path_length({-2, 0}, {2, 0});
  ASSERT_TRUE(len.has_value());
  // Around an end at y = +-3.25: at least 2 * hypot(2, 3.25).
  EXPECT_GT(*len, 7.5);
  EXPECT_LT(*len, 8.5);
  EXPECT_NEAR(*w.path_length({-2, -4}, {2, -4}), 4.0, 0.05);  // past the wall's end: straight
}

TEST(NavWorld, YawedWallLandsAlongItsHeading) {
  NavWorldConfig c = open_field();
  const double yaw = M_PI / 3;
  c.walls = {{{1, 1}, {6, 0.5}, yaw}};
  NavWorld w(c);
  const Vec2 along = Vec2{1, 1} + 2.5 * heading_vector(yaw);
  const Vec2 across = Vec2{1, 1} + 2.0 * heading_vector(yaw + M_PI / 2);
  const Vec2 mirrored =
      Vec2{1, 1} + 2.5 * heading_vector(-yaw);  // where a flipped yaw would put it
  EXPECT_FALSE(w.on_mesh(along));
  EXPECT_FALSE(w.on_mesh({1, 1}));
  EXPECT_TRUE(w.on_mesh(across));
  EXPECT_TRUE(w.on_mesh(mirrored));
  EXPECT_TRUE(w.on_mesh({3.5, 1}));  // where an unrotated wall would end
}

TEST(NavWorld, NoPathThroughAClosedWall) {
  NavWorldConfig c = open_field();
  c.walls = {{{0, 0}, {0.5, 12}, 0.0}};
  NavWorld w(c);
  EXPECT_FALSE(w.has_path({-2, 0}, {2, 0}));
  EXPECT_FALSE(w.path_length({-2, 0}, {2, 0}).has_value());
  EXPECT_TRUE(w.has_path({-2, 0}, {-2, 3}));
}

TEST(NavWorld, ExtraGeometryIsWalkable) {
  NavWorldConfig c = open_field();
  c.walls = {{{0, 0}, {0.5, 12}, 0.0}};  // closes the ground between the halves
  // A bridge deck over the wall at z = 1.1 (above the wall, too high to step onto).
  const double z = 1.1;
  c.triangles = {{-2, -1, z}, {2, -1, z}, {2, 1, z}, {-2, -1, z}, {2, 1, z}, {-2, 1, z}};
  NavWorld w(c);
  EXPECT_FALSE(w.has_path({-3, 3}, {3, 3}));
  const auto nav = w.nearest_on_mesh({0, 0}, 0.1);
  ASSERT_TRUE(nav.has_value());                  // the deck is on the mesh above the wall
  EXPECT_TRUE(w.has_path({-1.5, 0}, {1.5, 0}));  // along the deck, over the wall
  EXPECT_FALSE(w.has_path({-3, 3}, {-1.5, 0}));  // too high to step onto from the ground
}

TEST(NavWorld, ObstacleCarvesTheGapWhileDown) {
  NavWorldConfig c = one_gap();
  c.moving = {{{{0, 0}, {0.5, 2}, 0.0}, 20.0, 0.5, 0.0}};
  NavWorld w(c);
  EXPECT_TRUE(w.has_path({-2, 0}, {2, 0}));  // before the first update: up
  w.update(0.0, {});
  EXPECT_TRUE(w.obstacle_down(0));
  EXPECT_FALSE(w.has_path({-2, 0}, {2, 0}));
  EXPECT_TRUE(w.in_wall({0, 0.5}, 0.1));
  w.update(9.9, {});
  EXPECT_FALSE(w.has_path({-2, 0}, {2, 0}));
  w.update(10.0, {});
  EXPECT_FALSE(w.obstacle_down(0));
  EXPECT_TRUE(w.has_path({-2, 0}, {2, 0}));
  EXPECT_FALSE(w.in_wall({0, 0.5}, 0.1));
  w.update(20.0, {});
  EXPECT_FALSE(w.has_path({-2, 0}, {2, 0}));
  EXPECT_EQ(w.drops(), 2);
}

TEST(NavWorld, ObstacleYawTurnsItsFootprint) {
  // A 2 m x 0.5 m obstacle in the 2 m gap: turned a quarter it closes the
  // gap, unturned it leaves room on both sides.
  for (const double yaw : {0.0, M_PI / 2}) {
    NavWorldConfig c = one_gap();
    c.moving = {{{{0, 0}, {2, 0.5}, yaw}, 20.0, 0.5, 0.0}};
    NavWorld w(c);
    w.update(0.0, {});
    EXPECT_EQ(w.has_path({-2, 0}, {2, 0}), yaw == 0.0) << "yaw " << yaw;
  }
  // A sign check: a long thin obstacle at +30 degrees in the open.
  NavWorldConfig c = open_field();
  c.moving = {{{{0, 0}, {4, 0.3}, M_PI / 6}, 20.0, 0.5, 0.0}};
  NavWorld w(c);
  w.update(0.0, {});
  EXPECT_FALSE(w.on_mesh(1.5 * heading_vector(M_PI / 6)));
  EXPECT_TRUE(w.on_mesh(1.5 * heading_vector(-M_PI / 6)));
}

TEST(NavWorld, DropOverAnAgentIsDeferred) {
  NavWorldConfig c = one_gap();
  c.moving = {{{{0, 0}, {0.5, 2}, 0.0}, 20.0, 0.5, 0.0}};
  NavWorld w(c);
  std::vector<Agent> agents(1);
  agents[0].position = {0.4, 0.2};  // disc overlaps the footprint's edge
  w.update(0.0, agents);
  EXPECT_FALSE(w.obstacle_down(0));
  EXPECT_TRUE(w.has_path({-2, 0}, {2, 0}));
  w.update(0.1, agents);
  EXPECT_EQ(w.deferred_drops(), 1);  // one window, counted once
  agents[0].position = {1.5, 0.2};
  w.update(0.2, agents);
  EXPECT_TRUE(w.obstacle_down(0));
  EXPECT_FALSE(w.has_path({-2, 0}, {2, 0}));
  EXPECT_EQ(w.deferred_drops(), 1);
  EXPECT_EQ(w.drops(), 1);
}

// One figure walking from (-3, 0) to (3, 0) with the figure model of the
// crossing tests; returns the figure's track.
std::vector<Vec2> walk_one(NavWorld& w, double t_end) {
  std::vector<Agent> agents(1);
  agents[0].position = {-3, 0};
  Crowd crowd(w, agents);
  CrowdGroup g(crowd, agents, {0}, {{3, 0}, 0.5, 0.5, 1});
  std::vector<Vec2> desired(1), track;
  const std::vector<double> vmax{g.max_speed(0)};
  for (double t = 0; t < t_end; t += 0.1) {
    g.steer(t, 0.1, agents, desired);
    test::move_figures(agents, desired, vmax, 0.1, 0.6);
    track.push_back(agents[0].position);
  }
  return track;
}

TEST(CrowdCarving, WaitsAtAClosedGapAndPassesWhenItOpens) {
  NavWorldConfig c = one_gap();
  c.moving = {{{{0, 0}, {0.5, 2}, 0.0}, 40.0, 0.5, 0.0}};  // down for t in [0, 20)
  NavWorld w(c);
  const auto track = walk_one(w, 45.0);
  for (std::size_t i = 0; i < 200; ++i) EXPECT_LT(track[i].x, -0.25) << "step " << i;
  EXPECT_GT(track[150].x, -2.0);  // it walked up to the wall and waited there
  EXPECT_NEAR(track.back().x, 3.0, 0.2);
  EXPECT_NEAR(track.back().y, 0.0, 0.2);
}

TEST(CrowdCarving, ReroutesThroughAnotherGap) {
  NavWorldConfig c = open_field();
  // Gaps at y in [-1, 1] (closed by the obstacle) and y in [3.5, 5].
  c.walls = {{{0, -3}, {0.5, 4}, 0.0}, {{0, 2.25}, {0.5, 2.5}, 0.0}};
  c.moving = {{{{0, 0}, {0.5, 2}, 0.0}, 200.0, 0.5, 0.0}};
  NavWorld w(c);
  const auto track = walk_one(w, 60.0);
  bool crossed = false;
  for (std::size_t i = 1; i < track.size(); ++i) {
    if (track[i - 1].x < 0 && track[i].x >= 0) {
      crossed = true;
      EXPECT_GT(track[i].y, 3.4);
    }
  }
  EXPECT_TRUE(crossed);
  EXPECT_NEAR(track.back().x, 3.0, 0.2);
}

}  // namespace
}  // namespace animrt::herd
