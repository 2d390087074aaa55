// The shipped scenes, run end to end through the herd: crowds reach their
// targets without touching, a flock keeps order behind its leader, and the
// moving obstacle holds the crowd back while down and lets it pass while up.

#include <gtest/gtest.h>

#include <string>

#include "animrt/controllers/herd/herd.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt::herd {
namespace {

std::string scene_path(const std::string& name) {
  return std::string(ANIMRT_SOURCE_DIR) + "/configs/herd/" + name;
}

std::string gait_of(const std::string& robot) { return load_robot_config(robot).motion.file; }

HerdMetrics run(Herd& herd) {
  const HerdScene& s = herd.scene();
  const long steps = std::lround(s.duration_s / s.step_s);
  const long per_output = std::max(1L, std::lround(1.0 / (s.output_hz * s.step_s)));
  herd.record_metrics();
  for (long k = 1; k <= steps; ++k) {
    herd.step();
    if (k % per_output == 0) herd.record_metrics();
  }
  return herd.metrics();
}

// Both layouts of the crossing: the teams head on through shared gaps, and
// each through a gap of its own.
TEST(HerdScenes, CrossingTeamsArriveWithoutTouching) {
  for (const char* scene : {"crossing.yaml", "crossing_own_gaps.yaml"}) {
    Herd herd(load_herd_scene(scene_path(scene)), gait_of);
    const HerdMetrics m = run(herd);
    EXPECT_EQ(m.collisions, 0) << scene << ": min clearance " << m.min_clearance_m;
    ASSERT_EQ(m.groups.size(), 2u);
    for (const GroupMetrics& g : m.groups) {
      EXPECT_EQ(g.arrivals, g.agents) << scene << ": " << g.name;
      EXPECT_LE(g.time_ratio_max, 2.0) << scene << ": " << g.name;
    }
  }
}

TEST(HerdScenes, ReynoldsFlockKeepsOrderBehindItsLeader) {
  Herd herd(load_herd_scene(scene_path("flock.yaml")), gait_of);
  const HerdMetrics m = run(herd);
  EXPECT_EQ(m.collisions, 0) << "min clearance " << m.min_clearance_m;
  const GroupMetrics& g = m.groups.at(0);
  EXPECT_EQ(g.kind, "reynolds");
  EXPECT_EQ(g.agents, 30);
  EXPECT_GE(g.order_mean, 0.9);
  EXPECT_GE(g.leader_distance_mean_m, 0.0);
}

TEST(HerdScenes, AnObstacleDownHoldsTheCrowdBackAndUpLetsItPass) {
  // The only way across x = 0 is the obstacle's gap; it is down for the
  // first 60 s, then up.
  Herd herd(load_herd_scene(scene_path("gate.yaml")), gait_of);
  const HerdScene& s = herd.scene();
  bool crossed_while_down = false;
  double first_across = -1.0;
  const auto across = [&] {
    for (const Agent& a : herd.agents()) {
      if (a.position.x > 0.3) return true;
    }
    return false;
  };
  while (herd.time() < s.duration_s) {
    herd.step();
    if (herd.time() < 60.0 && across()) crossed_while_down = true;
    if (first_across < 0 && across()) first_across = herd.time();
  }
  EXPECT_FALSE(crossed_while_down);
  EXPECT_GT(first_across, 60.0);
  int arrived = 0;
  for (int i = 0; i < static_cast<int>(herd.agents().size()); ++i)
    arrived += herd.arrived(i) ? 1 : 0;
  EXPECT_EQ(arrived, static_cast<int>(herd.agents().size()));
}

TEST(HerdScenes, SameSeedSameWalkOtherSeedOtherWalk) {
  const auto final_positions = [](std::uint64_t seed) {
    HerdScene scene = load_herd_scene(scene_path("flock.yaml"));
    scene.duration_s = 20;
    Herd herd(std::move(scene), gait_of, seed);
    while (herd.time() < 20) herd.step();
    std::vector<double> out;
    for (const Agent& a : herd.agents()) {
      out.push_back(a.position.x);
      out.push_back(a.position.y);
    }
    return out;
  };
  EXPECT_EQ(final_positions(5), final_positions(5));
  EXPECT_NE(final_positions(5), final_positions(6));
}

}  // namespace
}  // namespace animrt::herd
