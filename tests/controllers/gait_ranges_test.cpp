// Plausible ranges of a gait file's timing and size keys, and a calibration
// table's numbers and references: each key just past its bound is refused
// at its file, line and column; just inside it loads.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/gait/walk_response.hpp"
#include "animrt/core/error.hpp"
#include "controllers/gait_file_error.hpp"

namespace animrt {
namespace {
namespace gait_ranges_test {

const std::string kCurves =
    "curves: {hip: \"sin(2*PI*t)\"}\n"                                   // 3
    "limbs: {lf: 0, rf: 0.5}\n"                                          // 4
    "joints: {a: {curve: hip, limb: lf}, b: {curve: hip, limb: rf}}\n";  // 5

std::string gait(const std::string& timing, const std::string& steering = "") {
  return "name: g\n" + timing + "\n" + kCurves + steering;
}

// Line 7 onwards: a steering section whose one key is replaced.
std::string steered(const std::string& key, const std::string& value) {
  std::vector<std::pair<std::string, std::string>> keys = {{"min_froude", "0.05"},
                                                           {"max_froude", "0.1"},
                                                           {"max_turn_dps", "30"},
                                                           {"max_acceleration_m_s2", "0.3"},
                                                           {"hip_height_m", "0.2"},
                                                           {"track_width_m", "0.15"},
                                                           {"sides", "{left: [lf], right: [rf]}"}};
  std::string out = "steering:\n";
  for (auto& [k, v] : keys) out += "  " + k + ": " + (k == key ? value : v) + "\n";
  return out;
}

struct Case {
  std::string text;
  std::string error;  // expected prefix; empty: loads
};

TEST(GaitRanges, TimingKeysJustPastTheirBoundsAreRefusedAtTheirPosition) {
  const std::vector<Case> cases = {
      {gait("stride_frequency_hz: 10"), ""},
      {gait("stride_frequency_hz: 10.001"),
       "g.yaml:2:22: stride_frequency_hz: expected a number from 0.001 to 10, found \"10.001\""},
      {gait("stride_frequency_hz: 1e15"), "g.yaml:2:22: stride_frequency_hz: expected a number"},
      {gait("stride_frequency_hz: 0.001"), ""},
      {gait("stride_frequency_hz: 0.0009"),
       "g.yaml:2:22: stride_frequency_hz: expected a number from 0.001 to 10"},
      {gait("froude: {number: 10, hip_height_m: 1.5}"), ""},
      {gait("froude: {number: 10.01, hip_height_m: 1.5}"),
       "g.yaml:2:18: froude.number: expected a number from 1e-06 to 10, found \"10.01\""},
      {gait("froude: {number: 0.4, hip_height_m: 10}"), ""},
      {gait("froude: {number: 0.4, hip_height_m: 10.01}"),
       "g.yaml:2:37: froude.hip_height_m: expected a number from 0.01 to 10, found \"10.01\""},
      {gait("froude: {number: 0.4, hip_height_m: 1e30}"),
       "g.yaml:2:37: froude.hip_height_m: expected a number from 0.01 to 10"},
      {gait("froude: {number: 0.01, hip_height_m: 0.01}"), ""},
      {gait("froude: {number: 0.4, hip_height_m: 0.0099}"),
       "g.yaml:2:37: froude.hip_height_m: expected a number from 0.01 to 10"},
      // Both in range, the stride they make is not (34 Hz).
      {gait("froude: {number: 10, hip_height_m: 0.01}"),
       "g.yaml:2:9: froude: number 10 at hip_height_m 0.01 is a stride frequency of"},
  };
  for (const Case& c : cases) {
    const std::string error = gait_file_error(c.text);
    if (c.error.empty()) {
      EXPECT_EQ(error, "no error") << c.text;
    } else {
      EXPECT_EQ(error.substr(0, c.error.size()), c.error) << c.text;
    }
  }
}

TEST(GaitRanges, SteeringSizesJustPastTheirBoundsAreRefusedAtTheirPosition) {
  const std::string timing = "stride_frequency_hz: 1";
  const std::vector<Case> cases = {
      {gait(timing, steered("max_acceleration_m_s2", "50")), ""},
      {gait(timing, steered("max_acceleration_m_s2", "50.1")),
       "g.yaml:10:26: steering.max_acceleration_m_s2: expected a number from 1e-06 to 50, found "
       "\"50.1\""},
      {gait(timing, steered("hip_height_m", "10")), ""},
      {gait(timing, steered("hip_height_m", "10.5")),
       "g.yaml:11:17: steering.hip_height_m: expected a number from 0.01 to 10, found \"10.5\""},
      {gait(timing, steered("hip_height_m", "0.005")),
       "g.yaml:11:17: steering.hip_height_m: expected a number from 0.01 to 10"},
      {gait(timing, steered("track_width_m", "10")), ""},
      {gait(timing, steered("track_width_m", "10.5")),
       "g.yaml:12:18: steering.track_width_m: expected a number from 0.001 to 10, found \"10.5\""},
  };
  for (const Case& c : cases) {
    const std::string error = gait_file_error(c.text);
    if (c.error.empty()) {
      EXPECT_EQ(error, "no error") << c.text;
    } else {
      EXPECT_EQ(error.substr(0, c.error.size()), c.error) << c.text;
    }
  }
}

TEST(GaitRanges, ValidateChecksTheSameRangesInMemory) {
  GaitFile g = parse_gait_file(gait("stride_frequency_hz: 1", steered("", "")), "g.yaml");
  EXPECT_NO_THROW(validate_gait(g));
  GaitFile fast = g;
  fast.stride_frequency_hz = 1e15;
  EXPECT_THROW(validate_gait(fast), InputError);
  GaitFile tall = g;
  tall.stride_frequency_hz.reset();
  tall.froude = FroudeTiming{0.4, 1e30};
  EXPECT_THROW(validate_gait(tall), InputError);
  GaitFile quick = g;
  quick.steering->max_acceleration_m_s2 = 1e9;
  EXPECT_THROW(validate_gait(quick), InputError);
}

// ---- calibration tables ----

std::string calibration_error(const std::string& text) {
  try {
    (void)parse_gait_calibration(text, "c.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string point(const std::string& speed, const std::string& turn, bool fell) {
  return "  - {speed_m_s: 0.1, turn_dps: 0, achieved_speed_m_s: " + speed +
         ", achieved_turn_dps: " + turn + ", fell: " + (fell ? "true" : "false") + "}\n";
}

TEST(CalibrationRanges, AchievedMotionJustPastItsBoundsIsRefusedAtItsPosition) {
  const std::string head = "gait: w.yaml\nmodel: m.xml\ntolerance: 0.15\npoints:\n";
  EXPECT_EQ(calibration_error(head + point("100", "36000", true)), "no error");
  EXPECT_EQ(calibration_error(head + point("-100", "-36000", true)), "no error");
  EXPECT_EQ(calibration_error(head + point("100.5", "0", true)),
            "c.yaml:5:55: points[0].achieved_speed_m_s: expected a number from -100 to 100, found "
            "\"100.5\"");
  EXPECT_EQ(calibration_error(head + point("0", "-36001", true)),
            "c.yaml:5:77: points[0].achieved_turn_dps: expected a number from -36000 to 36000, "
            "found \"-36001\"");
  EXPECT_EQ(calibration_error("gait: \"\"\nmodel: m.xml\ntolerance: 0.15\npoints: []\n"),
            "c.yaml:1:7: gait: expected the gait file it was measured for, found \"\"");
}

struct Folder {
  std::filesystem::path dir;
  Folder() {
    dir = std::filesystem::temp_directory_path() / "calibration_references";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~Folder() { std::filesystem::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

std::string walk_response_error(const std::string& gait_path) {
  try {
    (void)load_walk_response(gait_path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CalibrationRanges, TheTablesGaitAndModelReferencesAreChecked) {
  const Folder f;
  const std::string text = gait("stride_frequency_hz: 1", steered("", ""));
  const std::string walk = f.write("walk.yaml", text);
  f.write("other.yaml", text);
  f.write("figure.xml", "<mujoco/>\n");
  const std::string table =
      "tolerance: 0.15\npoints:\n  - {speed_m_s: 0.1, turn_dps: 0, achieved_speed_m_s: 0.1, "
      "achieved_turn_dps: 0, fell: false}\n";
  const std::string cal = calibration_path_for(walk);

  f.write("walk.calibration.yaml", "gait: walk.yaml\nmodel: figure.xml\n" + table);
  EXPECT_EQ(walk_response_error(walk), "no error");

  // Measured for another gait: the table would steer this one wrongly.
  f.write("walk.calibration.yaml", "gait: other.yaml\nmodel: figure.xml\n" + table);
  std::string e = walk_response_error(walk);
  EXPECT_EQ(e.rfind(cal + ":1:7: gait: this table was measured for \"other.yaml\"", 0), 0u) << e;

  f.write("walk.calibration.yaml", "gait: gone.yaml\nmodel: figure.xml\n" + table);
  e = walk_response_error(walk);
  EXPECT_EQ(e.rfind(cal + ":1:7: gait: gait file \"gone.yaml\"", 0), 0u) << e;
  EXPECT_NE(e.find("does not exist"), std::string::npos) << e;

  f.write("walk.calibration.yaml", "gait: walk.yaml\nmodel: gone.xml\n" + table);
  e = walk_response_error(walk);
  EXPECT_EQ(e.rfind(cal + ":2:8: model: model file \"gone.xml\"", 0), 0u) << e;
  EXPECT_NE(e.find("does not exist"), std::string::npos) << e;

  // A folder is not a model.
  std::filesystem::create_directories(f.dir / "folder.xml");
  f.write("walk.calibration.yaml", "gait: walk.yaml\nmodel: folder.xml\n" + table);
  e = walk_response_error(walk);
  EXPECT_EQ(e.rfind(cal + ":2:8: model:", 0), 0u) << e;
}

}  // namespace gait_ranges_test
}  // namespace
}  // namespace animrt
