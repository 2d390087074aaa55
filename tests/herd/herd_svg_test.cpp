// The top view reads on its own: a legend names every group, a scale bar
// gives metres, each figure's start is marked and a flock's leader's path
// is drawn.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/controllers/herd/herd.hpp"
#include "animrt/controllers/herd/herd_output.hpp"

namespace animrt::herd {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) / name).string();
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(HerdSvg, LegendScaleStartMarksAndLeaderPath) {
  const std::string scene_path = temp_path("svg_scene.yaml");
  std::ofstream(scene_path)
      << "bounds_m: [-10, -5, 10, 5]\nduration_s: 5\nfigures:\n  pony: {gait: " << ANIMRT_SOURCE_DIR
      << "/configs/gaits/herd_pony.yaml, radius_m: 0.25}\n"
      << "groups:\n  - {name: sheep<1>, kind: reynolds, figure: pony, count: 4, "
         "spawn_m: [-4, -2, 0, 2], leader: {wander_m: [-8, -4, 8, 4], speed_mps: 0.08}}\n"
      << "  - {name: team, kind: reynolds, figure: pony, count: 3, spawn_m: [2, -2, 6, 2], "
         "leader: {wander_m: [-8, -4, 8, 4], speed_mps: 0.08}}\n";
  const auto svg_robot_gait = [](const std::string&) -> std::string { return ""; };
  Herd herd(load_herd_scene(scene_path), svg_robot_gait);
  TrailRecorder trails;
  trails.sample(herd);
  for (int k = 0; k < 20; ++k) {
    herd.step();
    trails.sample(herd);
  }
  const std::string svg = trails.svg(herd);
  EXPECT_EQ(count(svg, "class=\"start\""), 7);   // one start mark per figure
  EXPECT_EQ(count(svg, "class=\"leader\""), 2);  // one leader path per flock
  EXPECT_EQ(count(svg, "<polyline"), 7);         // the trails, as before
  EXPECT_NE(svg.find("sheep&lt;1&gt; (reynolds flock, 4 figures)"), std::string::npos);
  EXPECT_NE(svg.find("team (reynolds flock, 3 figures)"), std::string::npos);
  EXPECT_NE(svg.find("leader's path"), std::string::npos);
  // 20 m wide: the longest round length within a fifth of it, 2 m (50 px).
  EXPECT_NE(svg.find(">2 m</text>"), std::string::npos);
  EXPECT_NE(svg.find("H60.0"), std::string::npos);  // from x 10 px to 60 px
}

}  // namespace
}  // namespace animrt::herd
