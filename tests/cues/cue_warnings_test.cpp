// A cue's motion is checked as a robot's is, and what it is warned of is
// kept: a show whose learned model was never measured against linear
// interpolation is loaded with one warning line naming the cue file's line.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "seqnet/tiny_joint_model.hpp"

namespace animrt::cue_warnings_test {
namespace {

namespace fs = std::filesystem;

TEST(CueWarnings, ALearnedModelNeverMeasuredAgainstInterpolationIsReportedAtLoad) {
  const fs::path dir = fs::temp_directory_path() / ("cue_warnings_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  seqnet::write_model_file((dir / "small.model").string(), seqnet::test::tiny_joint_model(0.1F));
  std::ofstream(dir / "learned.yaml")
      << "name: s\n"
         "learned: {model: small.model, frame_s: 0.04}\n"
         "joints:\n"
         "  hip: {interpolation: learned, keys: [[0, 0], [0.4, 20], [0.8, -15]]}\n"
         "  knee: {interpolation: learned, keys: [[0, 10], [0.4, 5], [0.8, 30]]}\n";
  std::ofstream(dir / "cues.yaml") << "idle: still\n"
                                      "cues:\n"
                                      "  still:\n"
                                      "    play: {pose: {hip: 0}}\n"
                                      "  step:\n"
                                      "    play: {show: learned.yaml}\n";
  RobotConfig robot =
      load_robot_config(std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml");
  robot.joints[0].name = "hip";
  robot.joints[1].name = "knee";
  for (int j = 0; j < 2; ++j)
    robot.joints[static_cast<std::size_t>(j)].limits = {deg_to_rad(-90), deg_to_rad(90), 3.0, 30.0};
  const LoadedCues loaded = load_cues((dir / "cues.yaml").string(), robot);
  ASSERT_EQ(loaded.warnings.size(), 1u);
  const std::string& w = loaded.warnings[0];
  EXPECT_EQ(w.rfind((dir / "cues.yaml").string() + ":6: cues.step.play.show: ", 0), 0u) << w;
  EXPECT_NE(w.find("never measured against linear interpolation"), std::string::npos) << w;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace animrt::cue_warnings_test
