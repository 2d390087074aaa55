// Figures of other groups (a flock, the embodied robot) are passive crowd
// agents: crowd members walk around them.
#include <DetourCrowd.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "herd/crowd_sim.hpp"

namespace animrt::herd {
namespace {

TEST(CrowdPassive, MembersWalkAroundFiguresOfOtherGroups) {
  NavWorldConfig c;
  c.bounds = {-5, -5, 5, 5};
  NavWorld w(c);
  std::vector<Agent> agents(2);
  agents[0].position = {-3, 0};
  agents[1].position = {0, 0.05};  // stands on the straight line, not a crowd member
  agents[1].group = 1;
  Crowd crowd(w, agents);
  CrowdGroup g(crowd, agents, {0}, {{3, 0}, 0.3, 0.3, 1});
  std::vector<Vec2> desired(2);
  const std::vector<double> vmax{g.max_speed(0), 0.0};
  double closest = 1e9;
  for (double t = 0; t < 40 && !g.arrived(0); t += 0.1) {
    g.steer(t, 0.1, agents, desired);
    EXPECT_EQ(desired[1], Vec2{});  // the crowd never steers another group's figure
    test::move_figures(agents, desired, vmax, 0.1, 0.6);
    closest = std::min(closest, norm(agents[0].position - agents[1].position));
  }
  EXPECT_TRUE(g.arrived(0));
  EXPECT_GT(closest, agents[0].radius + agents[1].radius);
}

// A passive figure far from every member costs the crowd's update
// nothing: it sits out until it comes near one, then takes part again.
TEST(CrowdPassive, FarFiguresSitOutTheCrowdUpdateUntilTheyComeNear) {
  NavWorldConfig c;
  c.bounds = {-40, -5, 40, 5};
  NavWorld w(c);
  std::vector<Agent> agents(3);
  agents[0].position = {-30, 0};
  agents[1].position = {-28, 2};  // near the member
  agents[2].position = {30, 0};   // 60 m away
  agents[1].group = agents[2].group = 1;
  Crowd crowd(w, agents);
  CrowdGroup g(crowd, agents, {0}, {{-25, 0}, 0.3, 0.3, 1});
  std::vector<Vec2> desired(3);
  g.steer(0.0, 0.1, agents, desired);
  EXPECT_TRUE(crowd.native()->getAgent(0)->active);
  EXPECT_TRUE(crowd.native()->getAgent(1)->active);
  EXPECT_FALSE(crowd.native()->getAgent(2)->active);
  agents[2].position = {-29, -2};
  g.steer(0.1, 0.1, agents, desired);
  EXPECT_TRUE(crowd.native()->getAgent(2)->active);
  EXPECT_NEAR(crowd.native()->getAgent(2)->npos[0], -29.0f, 1e-4f);
}

}  // namespace
}  // namespace animrt::herd
