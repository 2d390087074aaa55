// Speech-driven head motion as a cue: the head robot's cue file names a
// sound and the head model; the cue crossfades in from the idle pose, talks
// (the jaw follows the sound) for the sound's length, and hands back to the
// idle cue. Asked for again, it speaks from the start again.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/head/audio.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt::head_cue_test {
namespace {

const std::string kRoot = ANIMRT_SOURCE_DIR;

std::string head_cues(const std::string& extra = "",
                      const std::string& audio = kRoot + "/configs/head/utterance.wav",
                      bool repeat = false) {
  const std::string path = ::testing::TempDir() + "/head_cues.yaml";
  std::ofstream(path) << "idle: rest\n"
                         "crossfade_s: 0.3\n"
                         "cues:\n"
                         "  rest:\n"
                         "    play: {pose: {neck_pitch: -5}}\n"
                         "  talk:\n"
                         "    play:\n"
                         "      head:\n"
                         "        model: "
                      << kRoot
                      << "/configs/head/model.txt\n"
                         "        audio: "
                      << audio << "\n        repeat: " << (repeat ? "true" : "false") << "\n"
                      << extra
                      << "        axes: {yaw: {joint: neck_yaw}, pitch: {joint: neck_pitch}}\n"
                         "        jaw: {joint: jaw, closed_deg: 0, open_deg: 20}\n";
  return path;
}

int joint(const RobotConfig& robot, const std::string& name) {
  for (std::size_t j = 0; j < robot.joints.size(); ++j) {
    if (robot.joints[j].name == name) return static_cast<int>(j);
  }
  return -1;
}

TEST(HeadCue, CrossfadesInTalksForTheSoundsLengthAndHandsBack) {
  const RobotConfig robot = load_robot_config(kRoot + "/configs/robots/head.yaml");
  LoadedCues loaded = load_cues(head_cues(), robot);
  const int talk = find_cue(loaded.cues, "talk");
  ASSERT_GE(talk, 0);
  const double length = head::load_audio(kRoot + "/configs/head/utterance.wav").duration_s();
  EXPECT_DOUBLE_EQ(loaded.cues[static_cast<std::size_t>(talk)].steps[0].duration_s, length);
  CueRequests requests;
  CuePlayer player(std::move(loaded.cues), loaded.idle, robot.joints, requests);
  const auto jaw = static_cast<std::size_t>(joint(robot, "jaw"));
  const auto pitch = static_cast<std::size_t>(joint(robot, "neck_pitch"));
  std::vector<double> pose(robot.joints.size(), 0.0);
  const double dt = 0.01;
  std::vector<double> jaw_first, jaw_again;
  int k = 0;
  auto step = [&] {
    std::fill(pose.begin(), pose.end(), 0.0);
    player.sample(k++ * dt, pose);
  };
  for (int i = 0; i < 50; ++i) step();
  EXPECT_NEAR(pose[pitch], deg_to_rad(-5), 1e-12);
  requests.cue(talk);
  step();  // the crossfade begins where the idle pose is
  EXPECT_NEAR(pose[pitch], deg_to_rad(-5), deg_to_rad(0.01));
  EXPECT_NEAR(pose[jaw], 0.0, deg_to_rad(0.01));
  double jaw_max = 0;
  for (int i = 1; i < static_cast<int>(length / dt); ++i) {
    step();
    EXPECT_EQ(player.current_cue(), talk) << i;
    jaw_max = std::max(jaw_max, pose[jaw]);
    if (i >= 50 && i < 150) jaw_first.push_back(pose[jaw]);
  }
  EXPECT_GT(jaw_max, deg_to_rad(8));  // it talks
  for (int i = 0; i < 100; ++i) step();
  EXPECT_EQ(player.current_cue(), loaded.idle);  // the sound ended: back to idle
  EXPECT_NEAR(pose[pitch], deg_to_rad(-5), 1e-9);
  EXPECT_NEAR(pose[jaw], 0.0, 1e-9);
  requests.cue(talk);
  for (int i = 0; i < 150; ++i) {
    step();
    if (i >= 50) jaw_again.push_back(pose[jaw]);
  }
  EXPECT_EQ(player.starts(talk), 2u);
  // The same words from the start (the cue's time may differ in its last
  // bits, so a window may end a sample apart).
  ASSERT_EQ(jaw_first.size(), jaw_again.size());
  double differ = 0;
  for (std::size_t i = 0; i < jaw_first.size(); ++i)
    differ = std::max(differ, std::abs(jaw_first[i] - jaw_again[i]));
  EXPECT_LT(differ, deg_to_rad(0.2));
  EXPECT_GT(*std::max_element(jaw_again.begin(), jaw_again.end()), deg_to_rad(5));
}

TEST(HeadCue, ABadHeadStepNamesTheCueFileLineAndKey) {
  const RobotConfig robot = load_robot_config(kRoot + "/configs/robots/head.yaml");
  try {
    load_cues(head_cues("        smoothing: fast\n"), robot);
    FAIL() << "loaded";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("head_cues.yaml:12"), std::string::npos) << what;
    EXPECT_NE(what.find("smoothing"), std::string::npos) << what;
  }
}

// A head axis or jaw bound to a joint the robot lacks is named at the cue
// file's line and key (the binding used to be reported with the robot
// file's keys, motion.axes...).
TEST(HeadCue, AnUnknownJointIsNamedAtTheCueFilesKey) {
  const RobotConfig robot = load_robot_config(kRoot + "/configs/robots/head.yaml");
  const std::string good = head_cues();
  std::ifstream in(good);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  struct Case {
    std::string from, to, where, key;
  };
  for (const Case& c :
       {Case{"pitch: {joint: neck_pitch}", "pitch: {joint: neck_tilt}", "head_cues.yaml:12:",
             ": cues.talk.play.head.axes.pitch.joint: no joint named 'neck_tilt'"},
        Case{"jaw: {joint: jaw,", "jaw: {joint: mouth,",
             "head_cues.yaml:13:", ": cues.talk.play.head.jaw.joint: no joint named 'mouth'"}}) {
    std::string bad = text;
    bad.replace(bad.find(c.from), c.from.size(), c.to);
    std::ofstream(good) << bad;
    try {
      load_cues(good, robot);
      ADD_FAILURE() << "loaded with " << c.to;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.where), std::string::npos) << what;
      EXPECT_NE(what.find(c.key), std::string::npos) << what;
    }
  }
}

// A bad sound is an error at the cue file's line and key that name it, with
// the sound's own problem (it used to name only the WAV), whether the step
// plays for the sound's length or repeats it.
TEST(HeadCue, ABadSoundNamesTheCueFileLineAndKey) {
  const RobotConfig robot = load_robot_config(kRoot + "/configs/robots/head.yaml");
  const std::string wav = ::testing::TempDir() + "/head_cue_text.wav";
  std::ofstream(wav) << "hello this is not audio\n";
  for (const bool repeat : {false, true}) {
    const std::string cues = head_cues("", wav, repeat);
    try {
      load_cues(cues, robot);
      FAIL() << "loaded, repeat " << repeat;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where().file, cues);
      EXPECT_EQ(e.where().line, 10);
      EXPECT_EQ(e.key(), "cues.talk.play.head.audio");
      const std::string want = "audio file \"" + wav + "\": not a readable audio file";
      EXPECT_EQ(e.message().substr(0, want.size()), want) << e.what();
    }
  }
}

}  // namespace
}  // namespace animrt::head_cue_test
