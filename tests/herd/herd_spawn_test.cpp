// Where figures start: a spawn area that another group's area overlaps still
// takes its figures when there is room, and when there is none the error
// names the groups that fill it.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt::herd {
namespace {

std::string write_scene(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::path(::testing::TempDir()) / name).string();
  std::ofstream(path) << text;
  return path;
}

// Flock a (20 figures of radius 0.25 in a 4 m square) and flock b
// (`b_count`) in `b_area`, which overlaps a's.
std::string two_flocks(int b_count, const std::string& b_area) {
  const std::string leader = "leader: {wander_m: [-8, -8, 8, 8], speed_mps: 0.08}";
  return std::string("bounds_m: [-10, -10, 10, 10]\nduration_s: 1\n") +
         "figures:\n  pony: {gait: " + ANIMRT_SOURCE_DIR +
         "/configs/gaits/herd_pony.yaml, radius_m: 0.25}\n" +
         "groups:\n  - {name: a, kind: reynolds, figure: pony, count: 20, spawn_m: [0, 0, 4, 4], " +
         leader +
         "}\n  - {name: b, kind: reynolds, figure: pony, count: " + std::to_string(b_count) +
         ", spawn_m: " + b_area + ", " + leader + "}\n";
}

const auto no_robot_gait = [](const std::string&) -> std::string { return ""; };

TEST(HerdSpawn, AnOverlappedSpawnAreaWithRoomTakesItsFigures) {
  // a's 20 sampled figures leave b the strip x 4..6 and a's gaps, too few and
  // too narrow for sampling to find 12 places, room enough for a grid.
  Herd herd(load_herd_scene(write_scene("overlap.yaml", two_flocks(12, "[2, 0, 6, 4]"))),
            no_robot_gait);
  const auto agents = herd.agents();
  ASSERT_EQ(agents.size(), 32u);
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const Rect area = agents[i].group == 0 ? Rect{0, 0, 4, 4} : Rect{2, 0, 6, 4};
    EXPECT_TRUE(area.contains(agents[i].position)) << herd.agent_name(static_cast<int>(i));
    for (std::size_t j = i + 1; j < agents.size(); ++j) {
      EXPECT_GE(norm(agents[i].position - agents[j].position), 1.6 * 0.5 - 1e-9)
          << herd.agent_name(static_cast<int>(i)) << " " << herd.agent_name(static_cast<int>(j));
    }
  }
}

TEST(HerdSpawn, ASpawnAreaWithNoRoomNamesTheGroupThatFillsIt) {
  try {
    Herd herd(load_herd_scene(write_scene("full.yaml", two_flocks(30, "[0, 0, 4, 4]"))),
              no_robot_gait);
    FAIL() << "30 more figures were placed in a full 4 m square";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("full.yaml:"), std::string::npos) << what;
    EXPECT_NE(what.find("groups.b.spawn_m"), std::string::npos) << what;
    EXPECT_NE(what.find("no room for 30 figures"), std::string::npos) << what;
    EXPECT_NE(what.find("other groups' figures fill it: a (20 figures)"), std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace animrt::herd
