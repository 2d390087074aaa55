// The scene file: what loads, and one clear error (file, line, column, key)
// for each kind of mistake.

#include <gtest/gtest.h>

#include <string>

#include "animrt/controllers/herd/scene.hpp"

namespace animrt::herd {
namespace {

const std::string kFigures = std::string("figures:\n  pony: {robot: ") + ANIMRT_SOURCE_DIR +
                             "/configs/robots/quadruped.yaml, radius_m: 0.3}\n";

HerdScene parse(const std::string& text) {
  return parse_herd_scene(YamlNode::load_string(text, "scene.yaml"));
}

// The message of the error `text` raises ("" when it loads).
std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(HerdScene, LoadsEveryKey) {
  const HerdScene s = parse(
      "name: crossing\nseed: 7\nbounds_m: [-20, -10, 20, 10]\nstep_s: 0.05\noutput_hz: 5\n"
      "duration_s: 60\n"
      "walls:\n  - {center_m: [0, 4], size_m: [0.5, 6], yaw_deg: 90}\n"
      "moving_obstacles:\n  - {center_m: [0, -3], size_m: [0.5, 4], period_s: 8, down_fraction: "
      "0.25, "
      "phase_s: 2}\n" +
      kFigures +
      "groups:\n"
      "  - {name: red, kind: crowd, figure: pony, count: 20, spawn_m: [-18, -8, -14, 8],\n"
      "     target_m: [16, 0], speed_mps: [0.05, 0.1]}\n"
      "  - {name: flock, kind: reynolds, figure: pony, count: 30, spawn_m: [-5, -5, 5, 5],\n"
      "     leader: {wander_m: [-15, -8, 15, 8], speed_mps: 0.08, reach_m: 2}, params: "
      "{center_weight: 2}}\n");
  EXPECT_EQ(s.name, "crossing");
  EXPECT_EQ(s.seed, 7u);
  EXPECT_DOUBLE_EQ(s.bounds_m.xmin, -20);
  EXPECT_DOUBLE_EQ(s.bounds_m.ymax, 10);
  EXPECT_DOUBLE_EQ(s.step_s, 0.05);
  EXPECT_DOUBLE_EQ(s.output_hz, 5);
  EXPECT_DOUBLE_EQ(s.duration_s, 60);
  ASSERT_EQ(s.walls.size(), 1u);
  EXPECT_NEAR(s.walls[0].yaw_rad, 3.14159265358979 / 2, 1e-12);
  ASSERT_EQ(s.moving_obstacles.size(), 1u);
  EXPECT_DOUBLE_EQ(s.moving_obstacles[0].down_fraction, 0.25);
  EXPECT_DOUBLE_EQ(s.moving_obstacles[0].phase_s, 2);
  ASSERT_EQ(s.figures.size(), 1u);
  EXPECT_DOUBLE_EQ(s.figures[0].radius_m, 0.3);
  EXPECT_NE(s.figures[0].robot.find("quadruped.yaml"), std::string::npos);
  ASSERT_EQ(s.groups.size(), 2u);
  EXPECT_EQ(s.groups[0].kind, GroupKind::crowd);
  EXPECT_EQ(s.groups[0].count, 20);
  ASSERT_TRUE(s.groups[0].target_m.has_value());
  EXPECT_DOUBLE_EQ(s.groups[0].target_m->x, 16);
  EXPECT_DOUBLE_EQ(s.groups[0].speed_mps->second, 0.1);
  EXPECT_EQ(s.groups[1].kind, GroupKind::reynolds);
  ASSERT_TRUE(s.groups[1].leader.has_value());
  EXPECT_DOUBLE_EQ(s.groups[1].leader->reach_m, 2);
  ASSERT_TRUE(s.groups[1].params.has_value());
  EXPECT_EQ(s.agent_count(), 50);
}

const std::string kHead = "bounds_m: [-20, -10, 20, 10]\n" + kFigures + "groups:\n";

TEST(HerdScene, UnknownKeyNamesItsLine) {
  const std::string e =
      error_of(kHead +
               "  - {name: red, kind: crowd, figure: pony, count: 2, spawn_m: [-18, -8, -14, 8],\n"
               "     target_m: [16, 0], speed_mps: [0.05, 0.1], colour: red}\n");
  EXPECT_NE(e.find("scene.yaml:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("colour"), std::string::npos) << e;
}

TEST(HerdScene, FlockKeysAreNotCrowdKeys) {
  const std::string e =
      error_of(kHead +
               "  - {name: f, kind: unity, figure: pony, count: 2, spawn_m: [-1, -1, 1, 1],\n"
               "     leader: {wander_m: [-5, -5, 5, 5]}, target_m: [1, 1]}\n");
  EXPECT_NE(e.find("target_m"), std::string::npos) << e;
}

TEST(HerdScene, WrongTypeNamesTheKey) {
  const std::string e = error_of(
      kHead +
      "  - {name: red, kind: crowd, figure: pony, count: many, spawn_m: [-18, -8, -14, 8],\n"
      "     target_m: [16, 0], speed_mps: [0.05, 0.1]}\n");
  EXPECT_NE(e.find("groups[0].count"), std::string::npos) << e;
  EXPECT_NE(e.find("scene.yaml:5:"), std::string::npos) << e;
}

TEST(HerdScene, SpawnOutsideTheBounds) {
  const std::string e =
      error_of(kHead +
               "  - {name: red, kind: crowd, figure: pony, count: 2, spawn_m: [-25, -8, -14, 8],\n"
               "     target_m: [16, 0], speed_mps: [0.05, 0.1]}\n");
  EXPECT_NE(e.find("groups[0].spawn_m"), std::string::npos) << e;
  EXPECT_NE(e.find("inside bounds_m"), std::string::npos) << e;
}

// A wall or moving obstacle wholly off the ground does nothing: refused at
// its centre; one that reaches onto the ground (a boundary wall) is kept.
TEST(HerdScene, AWallWhollyOutsideTheBoundsIsRefused) {
  const std::string group =
      "  - {name: red, kind: crowd, figure: pony, count: 2, spawn_m: [-18, -8, -14, 8],\n"
      "     target_m: [16, 0], speed_mps: [0.05, 0.1]}\n";
  std::string e = error_of("walls:\n  - {center_m: [1000, 0], size_m: [1, 4]}\n" + kHead + group);
  EXPECT_NE(e.find("scene.yaml:2:16: walls[0].center_m: the wall lies wholly outside bounds_m"),
            std::string::npos)
      << e;
  e = error_of("moving_obstacles:\n  - {center_m: [0, -30], size_m: [2, 2]}\n" + kHead + group);
  EXPECT_NE(e.find("moving_obstacles[0].center_m: the obstacle lies wholly outside bounds_m"),
            std::string::npos)
      << e;
  // Half on the ground; and turned 90 degrees so that its length reaches in.
  EXPECT_EQ(error_of("walls:\n  - {center_m: [20, 0], size_m: [2, 4]}\n"
                     "  - {center_m: [0, 13], size_m: [1, 8], yaw_deg: 0}\n" +
                     kHead + group),
            "");
  EXPECT_NE(
      error_of("walls:\n  - {center_m: [0, 13], size_m: [8, 1], yaw_deg: 0}\n" + kHead + group)
          .find("wholly outside"),
      std::string::npos);
  EXPECT_EQ(
      error_of("walls:\n  - {center_m: [0, 13], size_m: [8, 1], yaw_deg: 90}\n" + kHead + group),
      "");
}

TEST(HerdScene, TargetOutsideTheBounds) {
  const std::string e =
      error_of(kHead +
               "  - {name: red, kind: crowd, figure: pony, count: 2, spawn_m: [-18, -8, -14, 8],\n"
               "     target_m: [26, 0], speed_mps: [0.05, 0.1]}\n");
  EXPECT_NE(e.find("groups[0].target_m"), std::string::npos) << e;
}

TEST(HerdScene, UnknownFigureAndKind) {
  EXPECT_NE(
      error_of(kHead +
               "  - {name: red, kind: crowd, figure: horse, count: 2, spawn_m: [-18, -8, -14, 8],\n"
               "     target_m: [16, 0], speed_mps: [0.05, 0.1]}\n")
          .find("no figure named 'horse'"),
      std::string::npos);
  EXPECT_NE(
      error_of(kHead +
               "  - {name: red, kind: swarm, figure: pony, count: 2, spawn_m: [-18, -8, -14, 8]}\n")
          .find("groups[0].kind"),
      std::string::npos);
}

TEST(HerdScene, DuplicateGroupNames) {
  const std::string g =
      "  - {name: a, kind: unity, figure: pony, count: 2, spawn_m: [-1, -1, 1, 1],\n"
      "     leader: {wander_m: [-5, -5, 5, 5]}}\n";
  EXPECT_NE(error_of(kHead + g + g).find("already defined"), std::string::npos);
}

TEST(HerdScene, BadRectanglesAndSizes) {
  EXPECT_NE(error_of("bounds_m: [20, -10, -20, 10]\n" + kFigures + "groups: []\n").find("bounds_m"),
            std::string::npos);
  EXPECT_NE(
      error_of("bounds_m: [-20, -10, 20, 10]\nwalls:\n  - {center_m: [0, 0], size_m: [0, 1]}\n" +
               kFigures + "groups: []\n")
          .find("walls[0].size_m"),
      std::string::npos);
  EXPECT_NE(
      error_of(kHead +
               "  - {name: red, kind: crowd, figure: pony, count: 2, spawn_m: [-18, -8, -14, 8],\n"
               "     target_m: [16, 0], speed_mps: [0.2, 0.1]}\n")
          .find("speed_mps"),
      std::string::npos);
}

TEST(HerdScene, MissingFigureFile) {
  const std::string e = error_of(
      "bounds_m: [-20, -10, 20, 10]\nfigures:\n  pony: {robot: no/such/robot.yaml}\ngroups: []\n");
  EXPECT_NE(e.find("figures.pony.robot"), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;
}

}  // namespace
}  // namespace animrt::herd
