// Errors a herd meets as it is built from a valid scene file (figures'
// gaits, targets on the mesh), each told at the scene's line and key.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt::herd::load_errors_test {
namespace {

const std::string kRoot = ANIMRT_SOURCE_DIR;

// The error building a herd of one crowd team from `figure` (a figures
// entry) and `target` raises, "" when it builds; a wall stands at x = 5.
std::string build_error(const std::string& figure, const std::string& target) {
  const std::string text =
      "bounds_m: [-10, -10, 10, 10]\n"
      "duration_s: 10\n"
      "walls:\n"
      "  - {center_m: [5, 0], size_m: [1, 4]}\n"
      "figures:\n"
      "  " +
      figure +
      "\n"
      "groups:\n"
      "  - {name: t, kind: crowd, figure: f, count: 2, spawn_m: [-8, -2, -6, 2],\n"
      "     target_m: " +
      target + ", speed_mps: [0.1, 0.12]}\n";
  try {
    Herd herd(parse_herd_scene(YamlNode::load_string(text, "scene.yaml")),
              [](const std::string&) { return std::string(); });
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kPony = "f: {gait: " + kRoot + "/configs/gaits/pony.yaml, radius_m: 0.25}";

TEST(HerdLoadErrors, ATargetInAWallOrOffTheGroundIsToldAsSuch) {
  ASSERT_EQ(build_error(kPony, "[0, 0]"), "");
  // It said "no path from the spawn area to the target".
  const std::string in_wall = build_error(kPony, "[5, 0]");
  EXPECT_EQ(in_wall.find("scene.yaml:9:"), 0u) << in_wall;
  EXPECT_NE(in_wall.find("groups[0].target_m: the target is inside a wall; the nearest walkable "
                         "point is ["),
            std::string::npos)
      << in_wall;
  const std::string at_edge = build_error(kPony, "[9.95, 9.95]");
  EXPECT_NE(at_edge.find("the target is off the walkable ground (too near a wall or the ground's "
                         "edge for a figure's centre); the nearest walkable point is [9."),
            std::string::npos)
      << at_edge;
}

TEST(HerdLoadErrors, AGaitThatCannotSteerIsToldAtTheFigure) {
  const std::string e =
      build_error("f: {gait: " + kRoot + "/configs/gaits/horse_walk.yaml}", "[0, 0]");
  EXPECT_EQ(e.find("scene.yaml:6:"), 0u) << e;
  EXPECT_NE(e.find("figures.f.gait: " + kRoot + "/configs/gaits/horse_walk.yaml"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("has no steering section"), std::string::npos) << e;
}

TEST(HerdLoadErrors, ARobotFileGivenAsAGaitIsSaidToBeOne) {
  const std::string e = build_error("f: {gait: " + kRoot + "/configs/robots/pony.yaml}", "[0, 0]");
  EXPECT_NE(e.find("figures.f.gait: "), std::string::npos) << e;
  EXPECT_NE(e.find("(a robot file? give it as robot:"), std::string::npos) << e;
}

// The warnings of a herd of one team of `figure`, which reaches its target.
std::vector<std::string> warnings_of(const std::string& figure) {
  const std::string text =
      "bounds_m: [-10, -10, 10, 10]\n"
      "duration_s: 10\n"
      "figures:\n"
      "  " +
      figure +
      "\n"
      "groups:\n"
      "  - {name: t, kind: crowd, figure: f, count: 1, spawn_m: [-8, -2, -6, 2],\n"
      "     target_m: [0, 0], speed_mps: [0.07, 0.07]}\n";
  Herd herd(parse_herd_scene(YamlNode::load_string(text, "scene.yaml")),
            [](const std::string&) { return std::string(); });
  return herd.warnings();
}

// The demo quadruped's calibration has no usable turning walk: it walked
// off its way for good (0 of 1 home 18 m straight ahead) without a word.
TEST(HerdLoadErrors, AFigureWhoseGaitCannotTurnIsWarnedOf) {
  const std::vector<std::string> w =
      warnings_of("f: {gait: " + kRoot + "/configs/gaits/walk.yaml, radius_m: 0.2}");
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].rfind("warning: scene.yaml:4:6: figures.f: its gait turns at most 0.", 0), 0u)
      << w[0];
  EXPECT_TRUE(warnings_of(kPony).empty());
}

}  // namespace
}  // namespace animrt::herd::load_errors_test
