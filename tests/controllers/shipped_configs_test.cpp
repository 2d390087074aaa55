// Every gait, calibration table, herd scene, show and evolve run file under
// configs/ loads with the ranges its loader checks (robot files: the CLI's
// validate test).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/gait/walk_response.hpp"
#include "animrt/controllers/herd/scene.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "animrt/learn/evolve/run_config.hpp"
#include "support/files.hpp"

namespace animrt {
namespace {
namespace shipped_configs_test {

namespace fs = std::filesystem;

std::vector<std::string> files_in(const std::string& folder, const std::string& suffix) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(kConfigsDir + "/" + folder)) {
    const std::string p = e.path().string();
    if (p.size() >= suffix.size() &&
        p.compare(p.size() - suffix.size(), suffix.size(), suffix) == 0)
      out.push_back(p);
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool is_calibration(const std::string& p) {
  return p.find(".calibration.yaml") != std::string::npos;
}

TEST(ShippedConfigs, EveryGaitAndCalibrationTableLoads) {
  int gaits = 0, calibrated = 0;
  for (const std::string& path : files_in("gaits", ".yaml")) {
    if (is_calibration(path)) continue;
    ++gaits;
    const GaitFile gait = load_gait_file(path);
    EXPECT_NO_THROW(validate_gait(gait)) << path;
    if (!gait.steering) continue;
    EXPECT_NO_THROW((void)load_walk_response(path)) << path;
    calibrated += fs::exists(calibration_path_for(path)) ? 1 : 0;
  }
  EXPECT_GE(gaits, 9);
  EXPECT_GE(calibrated, 3);
  // No table is left without its gait.
  for (const std::string& path : files_in("gaits", ".calibration.yaml")) {
    const std::string gait = path.substr(0, path.size() - 17) + ".yaml";
    EXPECT_TRUE(fs::exists(gait)) << path;
  }
}

TEST(ShippedConfigs, EveryHerdSceneShowAndEvolveRunLoads) {
  for (const std::string& path : files_in("herd", ".yaml")) {
    try {
      const herd::HerdScene scene = herd::load_herd_scene(path);
      for (const herd::FigureSpec& f : scene.figures) {
        if (!f.gait.empty()) (void)load_walk_response(f.gait);
      }
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  // The shows folder holds gaits that move a figure's parts too.
  for (const std::string& path : files_in("shows", ".yaml")) {
    try {
      if (YamlNode::load_file(path).has("curves")) {
        validate_gait(load_gait_file(path));
      } else {
        (void)load_show_file(path);
      }
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  for (const std::string& path : files_in("evolve", ".yaml")) {
    try {
      const evolve::RunConfig run = evolve::load_run_config(path);
      validate_gait(load_gait_file(run.seed_gait));
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

}  // namespace shipped_configs_test
}  // namespace
}  // namespace animrt
