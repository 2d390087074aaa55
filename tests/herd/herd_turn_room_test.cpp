// The contact guard keeps a crowd figure that turns only while it walks
// (the maze's uncalibrated pony: slowest walk 0.02 m/s, 45 deg/s) the room
// to walk its turn away from a figure it faces: at contact every step of
// that turn would close on the other, and it would stand there for good
// (maze seed 21, docs/results/herds.md).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "animrt/controllers/herd/figure.hpp"
#include "animrt/controllers/herd/herd.hpp"
#include "support/files.hpp"

namespace animrt::herd::turn_room_test {
namespace {

// Two crowds of one figure each: red goes home to the west, blue to the east.
std::string two_figures() {
  return std::string("bounds_m: [-10, -5, 10, 5]\nduration_s: 60\n") +
         "figures:\n  pony: {gait: " + ANIMRT_SOURCE_DIR +
         "/configs/gaits/herd_pony.yaml, radius_m: 0.25}\n" +
         "groups:\n"
         "  - {name: red, kind: crowd, figure: pony, count: 1, spawn_m: [-3, -1, -2, 1], "
         "target_m: [-8, 0], speed_mps: [0.15, 0.15]}\n"
         "  - {name: blue, kind: crowd, figure: pony, count: 1, spawn_m: [2, -1, 3, 1], "
         "target_m: [8, 0], speed_mps: [0.15, 0.15]}\n";
}

// The scene file in the tests' temporary folder.
Herd two_figures_herd() {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / "turn_room.yaml";
  write_file(path, two_figures());
  return Herd(load_herd_scene(path.string()), [](const std::string&) { return std::string(); });
}

TEST(HerdTurnRoom, TheMazesPonyTurnsOnlyWhileItWalks) {
  Herd herd = two_figures_herd();
  const Figure& pony = herd.figure(0);
  EXPECT_EQ(pony.walk.spot_turn(), 0.0);
  // 0.02 m/s at 45 deg/s.
  EXPECT_NEAR(turning_radius(pony), 0.02 / (std::numbers::pi / 4), 1e-3);
}

TEST(HerdTurnRoom, AFigureTurningRoundBeforeAnotherTurnsClearOfIt) {
  // Red walks east at 0.25 m/s toward blue, which stands facing it (its
  // own figure moves it: here, not at all), and must go back west: it slows
  // and turns round, and at the slowest walk its turn still carries it
  // toward blue. It stops short of contact, turns clear and goes home,
  // where at contact it could only stand (without the room, red stands
  // there from a gap of 10 cm or less).
  for (const double gap : {0.05, 0.1, 0.2, 0.4}) {
    for (const double slant : {0.0, 0.2, -0.4, 0.6}) {
      Herd herd = two_figures_herd();
      herd.embody(1);
      herd.set_pose(0, {0.0, 0.0}, slant, 0.25, 0.0);
      herd.set_pose(1, {0.5 + gap, 0.0}, std::numbers::pi, 0.0, 0.0);
      double closest = 1e9;
      for (int k = 0; k < 600; ++k) {
        herd.step();
        const auto a = herd.agents();
        closest = std::min(closest, norm(a[0].position - a[1].position));
      }
      const std::string at = "gap " + std::to_string(gap) + ", slant " + std::to_string(slant);
      EXPECT_GE(closest, 0.5 - 1e-9) << at;
      EXPECT_LT(herd.agents()[0].position.x, -3.0) << "red did not go home, " << at;
    }
  }
}

}  // namespace
}  // namespace animrt::herd::turn_room_test
