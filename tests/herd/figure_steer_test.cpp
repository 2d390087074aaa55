// A figure's command from its group's wish: stopping and starting a
// calibrated figure whose slowest walk is fast.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "animrt/controllers/gait/walk_response.hpp"
#include "animrt/controllers/herd/figure.hpp"

namespace animrt::herd {
namespace {

// A figure that walks 0.1-0.2 m/s straight and, where it `turns`, 0.2 rad/s
// either way, as measured; it cannot walk slower than 0.1 m/s. One that does
// not turn reaches no turn rate at any point of its table.
Figure calibrated_figure(bool turns = true) {
  GaitSteering s;
  s.min_froude = 0.05;
  s.max_froude = 0.2;
  s.max_turn_rad_s = 0.2;
  s.max_acceleration_m_s2 = 0.1;
  s.hip_height_m = 0.2;
  s.track_width_m = 0.2;
  s.left = {"l"};
  s.right = {"r"};
  GaitCalibration cal;
  for (double v : {0.1, 0.2}) {
    for (double w : {-0.2, 0.0, 0.2}) {
      CalibrationPoint p;
      p.commanded = {v, w};
      p.achieved = {v, turns ? w : 0.0};
      p.usable = calibration_usable(p, cal.tolerance);
      cal.points.push_back(p);
    }
  }
  return Figure{turns ? "pony" : "straight", 0.25, WalkResponse(s, &cal)};
}

TEST(FigureSteer, ASlowingFigureStandsBelowItsSlowestWalk) {
  const Figure f = calibrated_figure();
  Agent a;
  a.speed = 0.1;  // walking its slowest
  // Its group wants nothing: the ramp (0.1 - 0.01 m/s) is below the slowest
  // walk, so it stands instead of walking on at 0.1.
  MotionCommand c = steer_figure(f, a, Vec2{0.0, 0.0}, 0.1);
  EXPECT_EQ(c.speed_m_s, 0.0);
  EXPECT_EQ(c.turn_rad_s, 0.0);
  // Faster, it slows at its acceleration first.
  a.speed = 0.2;
  c = steer_figure(f, a, Vec2{0.0, 0.0}, 0.1);
  EXPECT_NEAR(c.speed_m_s, 0.19, 1e-3);
}

TEST(FigureSteer, AStandingFigureWalksOffAtItsSlowestWalkAndTurns) {
  const Figure f = calibrated_figure();
  Agent a;  // standing, heading +x
  // Wanted: 0.15 m/s to the left of its heading.
  const MotionCommand c = steer_figure(f, a, Vec2{0.0, 0.15}, 0.1);
  EXPECT_NEAR(c.speed_m_s, 0.1, 1e-3);
  EXPECT_NEAR(c.turn_rad_s, 0.2, 1e-3);  // its fastest usable turn, to the left
}

TEST(FigureSteer, AFigureThatCannotTurnStandsRatherThanWalkAwayFromItsWay) {
  // The same figure with every turning point unusable: it walks straight only.
  const Figure f = calibrated_figure(false);
  ASSERT_EQ(f.walk.max_turn(0.1), 0.0);
  Agent a;
  a.speed = 0.1;  // walking its slowest, heading +x
  // Its way is behind it (it walked past its goal): it stands.
  EXPECT_EQ(steer_figure(f, a, Vec2{-0.15, 0.02}, 0.1).speed_m_s, 0.0);
  // Ahead of it, it walks on.
  EXPECT_GT(steer_figure(f, a, Vec2{0.15, 0.02}, 0.1).speed_m_s, 0.0);
  // A figure that turns walks on while it turns toward a way behind it.
  const Figure turning = calibrated_figure();
  EXPECT_GT(steer_figure(turning, a, Vec2{-0.15, 0.02}, 0.1).speed_m_s, 0.0);
}

// The calibrated pony nose to a wall 5 cm ahead of its front, its way
// behind it: it turns round on the spot, no faster than its table's turn on
// the spot achieves and in the time that turn takes, and never closes on
// the wall. A figure that turns only while it walks walked into it.
TEST(FigureSteer, AFigureFacingAWallTurnsRoundOnTheSpot) {
  const Figure pony{
      "pony", 0.25,
      load_walk_response(std::string(ANIMRT_SOURCE_DIR) + "/configs/gaits/pony.yaml")};
  const WalkResponse& walk = pony.walk;
  ASSERT_GT(walk.spot_turn(), 0.0);
  const double left = walk.achieved({0.0, walk.spot_turn()}).turn_rad_s;
  const double right = -walk.achieved({0.0, -walk.spot_turn()}).turn_rad_s;
  const double fastest = std::max(left, right), slowest = std::min(left, right);
  ASSERT_GT(slowest, 0.0);
  Agent a;
  a.heading = 0.02;  // facing the wall at x = 0.3, a hair to the left
  const Vec2 away{-0.1, 0.0};
  const double dt = 0.1;
  double t = 0.0, spot_s = 0.0, nearest_wall = 0.3;
  while (std::cos(a.heading) > -0.95 && t < 120.0) {
    const MotionCommand c = steer_figure(pony, a, away, dt);
    walk_figure(pony, c, dt, a);
    if (c.speed_m_s == 0.0) {
      EXPECT_LE(std::abs(a.turn), fastest + 1e-9) << "t " << t;
      spot_s += dt;
    }
    nearest_wall = std::min(nearest_wall, 0.3 - a.position.x);
    t += dt;
  }
  // On the spot until its way is no longer behind it (heading pi/2), at
  // its calibrated rate; then it walks off, turning the rest of the way.
  const double angle = std::numbers::pi / 2 - 0.02;
  EXPECT_LT(std::cos(a.heading), -0.95);
  EXPECT_GE(spot_s, angle / fastest - dt);
  EXPECT_LE(spot_s, angle / slowest + dt);
  EXPECT_GE(nearest_wall, 0.3 - 1e-9) << "walked toward the wall";
}

// Stopped by the contact guard nose to a neighbour, with its way ahead: a
// figure that turns on the spot turns there, toward its way less the part
// that closes on the neighbour, or to the right when its way is straight
// into it; one that cannot stands.
TEST(FigureSteer, AFigureStoppedNoseToANeighbourTurnsOutOfItsWay) {
  const Figure pony{
      "pony", 0.25,
      load_walk_response(std::string(ANIMRT_SOURCE_DIR) + "/configs/gaits/pony.yaml")};
  const double spot = pony.walk.spot_turn();
  ASSERT_GT(spot, 0.0);
  Agent a;  // heading +x, the neighbour 0.5 m ahead
  const Vec2 toward{1.0, 0.0};
  MotionCommand c = turn_clear(pony, a, Vec2{0.1, 0.03}, toward);
  EXPECT_EQ(c.speed_m_s, 0.0);
  EXPECT_NEAR(c.turn_rad_s, spot, 1e-12);  // left, where its way leans
  c = turn_clear(pony, a, Vec2{0.1, 0.0}, toward);
  EXPECT_NEAR(c.turn_rad_s, -spot, 1e-12);  // straight into it: to the right
  // Its way already clear of the neighbour (along its side): it stands.
  a.heading = std::numbers::pi / 2;
  c = turn_clear(pony, a, Vec2{0.0, 0.1}, toward);
  EXPECT_NEAR(c.turn_rad_s, 0.0, 1e-12);
  const MotionCommand none = turn_clear(calibrated_figure(), a, Vec2{0.1, 0.0}, toward);
  EXPECT_EQ(none.speed_m_s, 0.0);
  EXPECT_EQ(none.turn_rad_s, 0.0);
}

}  // namespace
}  // namespace animrt::herd
