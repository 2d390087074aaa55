// A scene's OBJ geometry reaches the navigation mesh: a block around the
// crowd's target leaves it without a path (an error at the target), and the
// same scene without the block builds.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt::herd {
namespace {

std::string write(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::path(::testing::TempDir()) / name).string();
  std::ofstream(path) << text;
  return path;
}

std::string scene_text(bool with_block) {
  return std::string("bounds_m: [-5, -5, 5, 5]\n") +
         (with_block ? "geometry_obj: block.obj\n" : "") +
         "figures:\n  pony: {gait: " + ANIMRT_SOURCE_DIR + "/configs/gaits/herd_pony.yaml}\n" +
         "groups:\n  - {name: team, kind: crowd, figure: pony, count: 2, spawn_m: [-4, -4, -3, "
         "-3],\n"
         "     target_m: [0, 0], speed_mps: [0.1, 0.2]}\n";
}

TEST(HerdGeometry, AnObjBlockAroundTheTargetLeavesNoPath) {
  // A closed box, 2 m square and 1.2 m high, around the origin (z up).
  write("block.obj",
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv -1 -1 1.2\nv 1 -1 1.2\nv 1 1 1.2\nv -1 1 1.2\n"
        "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
        "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  const auto gait_of = [](const std::string&) -> std::string { return ""; };
  EXPECT_NO_THROW(Herd(load_herd_scene(write("open.yaml", scene_text(false))), gait_of));
  try {
    Herd herd(load_herd_scene(write("blocked.yaml", scene_text(true))), gait_of);
    FAIL() << "a target inside the block was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("blocked.yaml:"), std::string::npos) << what;
    EXPECT_NE(what.find("target_m"), std::string::npos) << what;
    EXPECT_NE(what.find("no path"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace animrt::herd
