// The cue file: what it plays, and one clear error (file, line, key) for
// each way it can be wrong, before anything moves.

#include "animrt/runtime/cue_file.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {
namespace {

const std::string kCueRoot = ANIMRT_SOURCE_DIR;

RobotConfig animatronic() {
  return load_robot_config(kCueRoot + "/configs/robots/animatronic.yaml");
}

// Writes a cue file beside the shipped shows, so their relative paths hold.
std::string write_cues(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << "# " << name << "\n" << text;
  return path;
}

std::string shows() { return kCueRoot + "/configs/shows/"; }

// The InputError's text, or "" when the file loads.
std::string load_error(const std::string& path) {
  try {
    load_cues(path, animatronic());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CueFile, ShippedCuesLoadWithTheirStepsAndHandovers) {
  const LoadedCues loaded = load_cues(kCueRoot + "/configs/cues/animatronic.yaml", animatronic());
  ASSERT_EQ(loaded.cues.size(), 4u);
  EXPECT_EQ(loaded.cues[static_cast<std::size_t>(loaded.idle)].name, "sway");
  const Cue& greet = loaded.cues[static_cast<std::size_t>(find_cue(loaded.cues, "greet"))];
  ASSERT_EQ(greet.steps.size(), 3u);
  EXPECT_DOUBLE_EQ(greet.steps[0].duration_s, 1.5);
  EXPECT_DOUBLE_EQ(greet.crossfade_s, 0.8);
  EXPECT_EQ(greet.then, -1);  // back to the idle cue
  const Cue& look = loaded.cues[static_cast<std::size_t>(find_cue(loaded.cues, "look_left"))];
  EXPECT_EQ(look.steps[0].duration_s, kForever);
  EXPECT_EQ(loaded.dmx_values[static_cast<std::size_t>(find_cue(loaded.cues, "hello"))], 2);
}

TEST(CueFile, EveryShippedCueFileLoadsForItsRobot) {
  int files = 0;
  for (const char* name : {"animatronic", "head"}) {
    const RobotConfig robot = load_robot_config(kCueRoot + "/configs/robots/" + name + ".yaml");
    const LoadedCues loaded = load_cues(kCueRoot + "/configs/cues/" + name + ".yaml", robot);
    EXPECT_GE(loaded.cues.size(), 2u) << name;
    ++files;
  }
  EXPECT_EQ(files, 2);
}

// The robot file's limits are kept in radians and 60 deg reads back as
// 59.99999999999999: a pose or a DMX range at a limit as written is
// taken (and held to it), one past it refused.
TEST(CueFile, APoseOrADmxRangeAtAJointsLimitIsTaken) {
  const RobotConfig robot = animatronic();
  const std::string at_limits =
      write_cues("at_limits.yaml",
                 "idle: rest\n"
                 "artnet: {universe: 0, joints: {neck_pan: {channel: 4, range: [-60, 60]}}}\n"
                 "cues:\n"
                 "  rest: {play: {pose: {neck_pan: 60, neck_tilt: -20, eye_pan: -30}}}\n"
                 "  far: {play: {pose: {neck_pan: -60, neck_tilt: 25}}}\n");
  ASSERT_EQ(load_error(at_limits), "");
  const LoadedCues loaded = load_cues(at_limits, robot);
  ASSERT_EQ(loaded.artnet.joints.size(), 1u);
  const JointLimits& pan =
      robot.joints[static_cast<std::size_t>(loaded.artnet.joints[0].joint)].limits;
  EXPECT_EQ(loaded.artnet.joints[0].min, pan.min_position);
  EXPECT_EQ(loaded.artnet.joints[0].max, pan.max_position);
  const std::string past = write_cues("past_limit.yaml",
                                      "idle: rest\n"
                                      "cues:\n"
                                      "  rest: {play: {pose: {neck_pan: 60.001}}}\n");
  EXPECT_NE(load_error(past).find(":4:34: cues.rest.play.pose.neck_pan: expected a number from -60 "
                                  "to 60, found \"60.001\""),
            std::string::npos)
      << load_error(past);
}

// A DMX joint's range of one position would leave the fader moving
// nothing: refused at the range, as written or as its limit holds it.
TEST(CueFile, ADmxRangeOfOnePositionIsRefused) {
  for (const char* range : {"[10, 10]", "[60, 60]", "[10.0, 1e1]"}) {
    const std::string path = write_cues(
        "one_position.yaml", std::string("idle: rest\n"
                                         "artnet: {universe: 0, joints: {neck_pan: {channel: 4, "
                                         "range: ") +
                                 range +
                                 "}}}\n"
                                 "cues:\n"
                                 "  rest: {play: {pose: {neck_pan: 0}}}\n");
    EXPECT_NE(load_error(path).find(":3:62: artnet.joints.neck_pan.range: both ends are one "
                                    "position"),
              std::string::npos)
        << range << ": " << load_error(path);
  }
}

TEST(CueFile, ACueNamingAMissingShowNamesFileLineAndKey) {
  const std::string path = write_cues("missing.yaml",
                                      "idle: rest\n"
                                      "cues:\n"
                                      "  rest: {play: {pose: {neck_pan: 0}}}\n"
                                      "  talk: {play: {show: " +
                                          shows() + "nothere.yaml}}\n");
  const std::string error = load_error(path);
  EXPECT_NE(error.find(path + ":5"), std::string::npos) << error;
  EXPECT_NE(error.find("cues.talk.play.show"), std::string::npos) << error;
  EXPECT_NE(error.find("file not found"), std::string::npos) << error;
}

TEST(CueFile, CuesThatHandOverInALoopWithoutAnExitAreRefused) {
  const std::string path =
      write_cues("ring.yaml",
                 "idle: rest\n"
                 "cues:\n"
                 "  rest: {play: {pose: {neck_pan: 0}}}\n"
                 "  a: {play: {pose: {neck_pan: 10}, duration_s: 1}, then: b}\n"
                 "  b: {play: {pose: {neck_pan: 20}, duration_s: 1}, then: a}\n");
  const std::string error = load_error(path);
  EXPECT_NE(error.find(path + ":5"), std::string::npos) << error;
  EXPECT_NE(error.find("cues.a.then"), std::string::npos) << error;
  EXPECT_NE(error.find("loop without an exit (a -> b -> a)"), std::string::npos) << error;
  // Through the idle cue it is no loop: a hands over to b, b to the idle cue.
  const std::string fine =
      write_cues("chain.yaml",
                 "idle: rest\n"
                 "cues:\n"
                 "  rest: {play: {pose: {neck_pan: 0}}}\n"
                 "  a: {play: {pose: {neck_pan: 10}, duration_s: 1}, then: b}\n"
                 "  b: {play: {pose: {neck_pan: 20}, duration_s: 1}, then: rest}\n");
  EXPECT_EQ(load_error(fine), "");
}

TEST(CueFile, UnknownKeysAndNamesAreRefusedWhereTheyAre) {
  const std::string key = write_cues("key.yaml",
                                     "idle: rest\n"
                                     "cues:\n"
                                     "  rest: {play: {pose: {neck_pan: 0}}, fade_s: 2}\n");
  std::string error = load_error(key);
  EXPECT_NE(error.find(key + ":4"), std::string::npos) << error;
  EXPECT_NE(error.find("fade_s"), std::string::npos) << error;

  const std::string idle = write_cues("idle.yaml",
                                      "idle: sleep\n"
                                      "cues:\n"
                                      "  rest: {play: {pose: {neck_pan: 0}}}\n");
  error = load_error(idle);
  EXPECT_NE(error.find(idle + ":2"), std::string::npos) << error;
  EXPECT_NE(error.find("no cue named \"sleep\" (the cues: rest)"), std::string::npos) << error;

  const std::string joint = write_cues("joint.yaml",
                                       "idle: rest\n"
                                       "cues:\n"
                                       "  rest: {play: {pose: {tail: 0}}}\n");
  error = load_error(joint);
  EXPECT_NE(error.find("cues.rest.play.pose.tail"), std::string::npos) << error;
}

TEST(CueFile, AStepThatNeverEndsBeforeOthersIsRefused) {
  const std::string path = write_cues("forever.yaml",
                                      "idle: rest\n"
                                      "cues:\n"
                                      "  rest: {play: {pose: {neck_pan: 0}}}\n"
                                      "  stuck:\n"
                                      "    play:\n"
                                      "      - {pose: {neck_pan: 30}}\n"
                                      "      - {pose: {neck_pan: 0}, duration_s: 1}\n");
  const std::string error = load_error(path);
  EXPECT_NE(error.find(path + ":7"), std::string::npos) << error;
  EXPECT_NE(error.find("never ends"), std::string::npos) << error;
}

// A step's duration is bounded as a show's is (1e6 s): 1e300 was accepted.
TEST(CueFile, AStepLongerThanAShowMayLastIsRefusedAtItsDuration) {
  const std::string path = write_cues("long.yaml",
                                      "idle: rest\n"
                                      "cues:\n"
                                      "  rest: {play: {pose: {neck_pan: 0}}}\n"
                                      "  wait:\n"
                                      "    play:\n"
                                      "      - {pose: {neck_pan: 30}, duration_s: 1e300}\n");
  EXPECT_EQ(load_error(path), path +
                                  ":7:44: cues.wait.play[0].duration_s: expected at most 1000000 "
                                  "s, found \"1e300\"");
  const std::string fine = write_cues("day.yaml",
                                      "idle: rest\n"
                                      "cues:\n"
                                      "  rest: {play: {pose: {neck_pan: 0}, duration_s: 1e6}}\n");
  EXPECT_EQ(load_error(fine), "");
}

}  // namespace
}  // namespace animrt
