// Plausible scene coordinates and sizes: each just past its bound is
// refused at its file, line and column; just inside it loads.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "animrt/controllers/herd/scene.hpp"

namespace animrt::herd {
namespace {
namespace scene_ranges_test {

// Line 1: bounds; line 2: a wall; line 3 onwards: figures and a group.
std::string scene(const std::string& bounds, const std::string& wall,
                  const std::string& spawn = "[-5, -5, 5, 5]",
                  const std::string& target = "[10, 0]", const std::string& wall_at = "[0, 4]") {
  return "bounds_m: " + bounds + "\nwalls:\n  - {center_m: " + wall_at + ", size_m: " + wall +
         "}\nfigures:\n  pony: {robot: " + ANIMRT_SOURCE_DIR +
         "/configs/robots/quadruped.yaml}\n"
         "groups:\n  - {name: red, kind: crowd, figure: pony, count: 2, spawn_m: " +
         spawn + ", target_m: " + target + ", speed_mps: [0.1, 0.2]}\n";
}

std::string error_of(const std::string& text) {
  try {
    parse_herd_scene(YamlNode::load_string(text, "scene.yaml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

struct Case {
  std::string text;
  std::string error;  // expected prefix; empty: loads
};

TEST(SceneRanges, CoordinatesAndSizesJustPastTheirBoundsAreRefusedAtTheirPosition) {
  const std::vector<Case> cases = {
      {scene("[-100, -100, 100, 100]", "[0.5, 200]"), ""},
      {scene("[-100, -100, 100.5, 100]", "[0.5, 6]"),
       "scene.yaml:1:11: bounds_m: expected an area at most 200 m a side, found 200.5 x 200 m"},
      {scene("[800, 800, 1000, 1000]", "[0.5, 6]", "[850, 850, 860, 860]", "[900, 900]",
             "[880, 880]"),
       ""},
      {scene("[800, 800, 1000, 1000.5]", "[0.5, 6]"),
       "scene.yaml:1:28: bounds_m[3]: expected a coordinate from -1000 to 1000 m, found "
       "\"1000.5\""},
      {scene("[-1e300, -10, 1e300, 10]", "[0.5, 6]"),
       "scene.yaml:1:12: bounds_m[0]: expected a coordinate from -1000 to 1000 m"},
      {scene("[-20, -10, 20, 10]", "[0.5, 200.5]"),
       "scene.yaml:3:32: walls[0].size_m: expected sizes up to 200 m, found "},
      {scene("[-20, -10, 20, 10]", "[0.5, 6]", "[-5, -5, 5, 5]", "[1001, 0]"), "scene.yaml:7:"},
  };
  for (const Case& c : cases) {
    const std::string error = error_of(c.text);
    if (c.error.empty()) {
      EXPECT_EQ(error, "no error") << c.text;
    } else {
      EXPECT_EQ(error.substr(0, c.error.size()), c.error) << c.text;
    }
  }
  // The target's coordinate is named as such, not only as outside the bounds.
  const std::string far =
      error_of(scene("[-20, -10, 20, 10]", "[0.5, 6]", "[-5, -5, 5, 5]", "[1001, 0]"));
  EXPECT_NE(far.find("groups[0].target_m[0]: expected a coordinate from -1000 to 1000 m"),
            std::string::npos)
      << far;
}

}  // namespace scene_ranges_test
}  // namespace
}  // namespace animrt::herd
