// Calibration tables and the walk response built from them.

#include "animrt/controllers/gait/walk_response.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/core/joint.hpp"

namespace animrt {
namespace {

GaitSteering steering() {
  GaitSteering s;
  s.min_froude = 0.05;
  s.max_froude = 0.1;
  s.max_turn_rad_s = 0.4;
  s.max_acceleration_m_s2 = 0.2;
  s.hip_height_m = 0.2;
  s.track_width_m = 0.2;
  s.left = {"l"};
  s.right = {"r"};
  return s;
}

CalibrationPoint point(double v, double w, double av, double aw, bool fell = false) {
  CalibrationPoint p;
  p.commanded = {v, w};
  p.achieved = {av, aw};
  p.fell = fell;
  p.usable = calibration_usable(p, 0.15);
  return p;
}

// Two speed levels, 0.1 and 0.2 m/s; at 0.2 the fastest right turn falls.
GaitCalibration table() {
  GaitCalibration c;
  c.gait_file = "walk.yaml";
  c.model_file = "quadruped.xml";
  c.points = {point(0.1, -0.2, 0.09, -0.19),  point(0.1, 0.0, 0.1, 0.0),
              point(0.1, 0.2, 0.11, 0.21),    point(0.2, -0.4, 0.1, -0.3, true),
              point(0.2, -0.1, 0.19, -0.095), point(0.2, 0.0, 0.18, 0.0),
              point(0.2, 0.1, 0.21, 0.105),   point(0.3, 0.0, 0.1, 0.0)};  // 67 % slow: not usable
  return c;
}

TEST(Calibration, UsableMeansNoFallAndWithinTolerance) {
  EXPECT_TRUE(point(0.1, 0, 0.114, 0).usable);
  EXPECT_FALSE(point(0.1, 0, 0.116, 0).usable);
  EXPECT_FALSE(point(0.1, 0, 0.1, 0, true).usable);
}

TEST(Calibration, UsableJudgesTheTurnToo) {
  const double w = deg_to_rad(20.0);
  EXPECT_TRUE(point(0.1, w, 0.1, 0.86 * w).usable);   // 14 % short
  EXPECT_TRUE(point(0.1, w, 0.1, 1.14 * w).usable);   // 14 % over
  EXPECT_FALSE(point(0.1, w, 0.1, 0.84 * w).usable);  // 16 % short
  EXPECT_FALSE(point(0.1, -w, 0.1, w).usable);        // the wrong way
  // The demo quadruped's turn points: 4 deg/s commanded, under 1 achieved.
  EXPECT_FALSE(point(0.0704, deg_to_rad(4.0), 0.0728, deg_to_rad(0.57)).usable);
  EXPECT_FALSE(point(0.0704, deg_to_rad(-4.0), 0.0734, deg_to_rad(-0.15)).usable);
  // Near zero the floor (kCalibrationTurnFloorDps) rules: a straight walk
  // may drift, a slow turn may miss, by up to 1 deg/s.
  EXPECT_TRUE(point(0.1, 0.0, 0.1, deg_to_rad(0.9)).usable);
  EXPECT_FALSE(point(0.1, 0.0, 0.1, deg_to_rad(-1.1)).usable);
  EXPECT_TRUE(point(0.1, deg_to_rad(2.0), 0.1, deg_to_rad(1.1)).usable);
  EXPECT_FALSE(point(0.1, deg_to_rad(2.0), 0.1, deg_to_rad(0.9)).usable);
}

TEST(Calibration, FileRoundTrips) {
  GaitCalibration c = table();
  c.points[1].achieved.turn_rad_s = 0.0123456789;
  const GaitCalibration back = parse_gait_calibration(format_gait_calibration(c), "c.yaml");
  EXPECT_EQ(back, c);
  const std::string path =
      (std::filesystem::temp_directory_path() / "round.calibration.yaml").string();
  write_gait_calibration(path, c);
  EXPECT_EQ(load_gait_calibration(path), c);
  std::filesystem::remove(path);
}

std::string calibration_error(const std::string& text) {
  try {
    (void)parse_gait_calibration(text, "c.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Calibration, BadFilesNameLineAndKey) {
  const std::string head = "gait: w.yaml\nmodel: m.xml\ntolerance: 0.15\npoints:\n";
  const std::string ok =
      "  - {speed_m_s: 0.1, turn_dps: 0, achieved_speed_m_s: 0.1, achieved_turn_dps: 0, "
      "fell: false}\n";
  EXPECT_EQ(calibration_error(head + ok), "no error");
  const std::string unknown = calibration_error(head + "  - {speed_m_s: 0.1, turn: 0}\n");
  EXPECT_NE(unknown.find("c.yaml:5:"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("points[0].turn"), std::string::npos) << unknown;
  const std::string missing = calibration_error(head + ok + "  - {speed_m_s: 0.1, turn_dps: 0}\n");
  EXPECT_NE(missing.find("c.yaml:6:"), std::string::npos) << missing;
  EXPECT_NE(missing.find("points[1]."), std::string::npos) << missing;
  EXPECT_NE(missing.find("required key is missing"), std::string::npos) << missing;
  // A usable flag the numbers contradict.
  const std::string liar = calibration_error(
      head +
      "  - {speed_m_s: 0.1, turn_dps: 0, achieved_speed_m_s: 0.5, achieved_turn_dps: 0, "
      "fell: false, usable: true}\n");
  EXPECT_NE(liar.find("c.yaml:5:"), std::string::npos) << liar;
  EXPECT_NE(liar.find("points[0].usable"), std::string::npos) << liar;
  // A missed turn called usable: the speed is right, the turn is not.
  const std::string turn_liar = calibration_error(
      head +
      "  - {speed_m_s: 0.1, turn_dps: 4, achieved_speed_m_s: 0.1, achieved_turn_dps: 0.5, "
      "fell: false, usable: true}\n");
  EXPECT_NE(turn_liar.find("c.yaml:5:"), std::string::npos) << turn_liar;
  EXPECT_NE(turn_liar.find("points[0].usable"), std::string::npos) << turn_liar;
  const std::string tol = calibration_error("gait: w\nmodel: m\ntolerance: 2\npoints: []\n");
  EXPECT_NE(tol.find("c.yaml:3:12: tolerance"), std::string::npos) << tol;
  // A table of no points calibrates nothing.
  EXPECT_EQ(calibration_error(head.substr(0, head.size() - 1) + " []\n"),
            "c.yaml:4:9: points: expected a list of points, found []");
  EXPECT_THROW(load_gait_calibration("/nonexistent/x.calibration.yaml"), InputError);
}

TEST(Calibration, PathSitsNextToTheGait) {
  EXPECT_EQ(calibration_path_for("configs/gaits/walk.yaml"), "configs/gaits/walk.calibration.yaml");
  EXPECT_EQ(calibration_path_for("walk.yaml"), "walk.calibration.yaml");
}

TEST(WalkResponse, WithoutCalibrationWalksWhatItIsToldWithinLimits) {
  const GaitSteering s = steering();
  const WalkResponse r(s);
  EXPECT_DOUBLE_EQ(r.min_speed(), s.min_speed_m_s());
  EXPECT_DOUBLE_EQ(r.max_speed(), s.max_speed_m_s());
  EXPECT_EQ(r.max_acceleration(), 0.2);
  EXPECT_EQ(r.max_turn(r.min_speed()), 0.4);
  EXPECT_EQ(r.max_turn(0.0), 0.0);
  const double mid = 0.5 * (r.min_speed() + r.max_speed());
  EXPECT_EQ(r.achieved({mid, 0.1}).speed_m_s, mid);
  EXPECT_EQ(r.achieved({mid, 0.1}).turn_rad_s, 0.1);
  EXPECT_EQ(r.achieved({10.0, 9.0}).speed_m_s, r.max_speed());
  EXPECT_EQ(r.achieved({10.0, 9.0}).turn_rad_s, 0.4);
  EXPECT_EQ(r.achieved({0.5 * r.min_speed(), 0.3}).speed_m_s, 0.0);  // stands
  EXPECT_EQ(r.achieved({0.5 * r.min_speed(), 0.3}).turn_rad_s, 0.0);
  const MotionCommand c = r.command_for({mid, -0.2});
  EXPECT_NEAR(c.speed_m_s, mid, 1e-3);
  EXPECT_NEAR(c.turn_rad_s, -0.2, 1e-3);
}

TEST(WalkResponse, InterpolatesTheUsablePoints) {
  const GaitCalibration cal = table();
  const WalkResponse r(steering(), &cal);
  EXPECT_EQ(r.min_speed(), 0.1);
  EXPECT_EQ(r.max_speed(), 0.2);  // 0.3 was not usable
  EXPECT_NEAR(r.max_turn(0.1), 0.2, 1e-12);
  EXPECT_NEAR(r.max_turn(0.2), 0.1, 1e-12);   // the faster right turn fell
  EXPECT_NEAR(r.max_turn(0.15), 0.1, 1e-12);  // the tighter of the two levels
  EXPECT_EQ(r.max_turn(0.25), 0.0);
  // On a point, between turns, between speeds.
  EXPECT_NEAR(r.achieved({0.2, 0.0}).speed_m_s, 0.18, 1e-12);
  EXPECT_NEAR(r.achieved({0.1, 0.1}).speed_m_s, 0.105, 1e-12);
  EXPECT_NEAR(r.achieved({0.1, 0.1}).turn_rad_s, 0.105, 1e-12);
  EXPECT_NEAR(r.achieved({0.15, 0.0}).speed_m_s, 0.14, 1e-12);
  // Clamped first: too fast is max speed, too tight is the usable turn.
  EXPECT_NEAR(r.achieved({0.5, 0.0}).speed_m_s, 0.18, 1e-12);
  EXPECT_NEAR(r.achieved({0.2, -1.0}).turn_rad_s, -0.095, 1e-12);
  EXPECT_EQ(r.achieved({0.05, 0.0}).speed_m_s, 0.0);
}

TEST(WalkResponse, CommandForFindsTheCommandThatAchievesTheWish) {
  const GaitCalibration cal = table();
  const WalkResponse r(steering(), &cal);
  // 0.18 m/s straight is achieved by commanding 0.2.
  MotionCommand c = r.command_for({0.18, 0.0});
  EXPECT_NEAR(c.speed_m_s, 0.2, 2e-3);
  EXPECT_NEAR(c.turn_rad_s, 0.0, 2e-3);
  EXPECT_NEAR(r.achieved(c).speed_m_s, 0.18, 1e-3);
  // A turn of 0.05 rad/s at 0.105 m/s is commanded a little slower, turning a little less.
  c = r.command_for({0.105, 0.05});
  EXPECT_NEAR(r.achieved(c).speed_m_s, 0.105, 2e-3);
  EXPECT_NEAR(r.achieved(c).turn_rad_s, 0.05, 2e-3);
  // Standing still is standing; beyond the range is the nearest usable.
  c = r.command_for({0.0, 0.0});
  EXPECT_EQ(c.speed_m_s, 0.0);
  c = r.command_for({1.0, 0.0});
  EXPECT_LE(c.speed_m_s, r.max_speed());
  // The fastest the table achieves: 0.21 m/s, at 0.2 m/s turning 0.1 rad/s.
  EXPECT_NEAR(r.achieved(c).speed_m_s, 0.21, 1e-3);
}

// Usable turns that do not reach the straight walk, and a usable speed cut
// off from the others by one that failed, are never commanded.
TEST(WalkResponse, NeverCommandsAnUnusableTurn) {
  GaitCalibration cal;
  cal.points = {// 0.1 m/s: straight and -0.2 usable; +0.2 hardly turns, so +0.4 (usable
                // on its own) is cut off, and -0.4 turns a quarter of what it was told.
                point(0.1, -0.4, 0.1, -0.1), point(0.1, -0.2, 0.1, -0.2), point(0.1, 0.0, 0.1, 0.0),
                point(0.1, 0.2, 0.1, 0.02), point(0.1, 0.4, 0.1, 0.4),
                // 0.2 m/s: straight and +-0.2 usable.
                point(0.2, -0.2, 0.2, -0.2), point(0.2, 0.0, 0.2, 0.0), point(0.2, 0.2, 0.2, 0.2),
                // 0.3 m/s: turns fine but the straight walk drifts 2 deg/s.
                point(0.3, -0.2, 0.3, -0.2), point(0.3, 0.0, 0.3, deg_to_rad(2.0)),
                point(0.3, 0.2, 0.3, 0.2),
                // 0.4 m/s: usable, but beyond the failed 0.3.
                point(0.4, 0.0, 0.4, 0.0)};
  ASSERT_FALSE(cal.points[0].usable);
  ASSERT_TRUE(cal.points[4].usable);
  ASSERT_FALSE(cal.points[9].usable);
  const WalkResponse r(steering(), &cal);
  EXPECT_EQ(r.min_speed(), 0.1);
  EXPECT_EQ(r.max_speed(), 0.2);
  EXPECT_EQ(r.max_turn(0.1), 0.0);  // the fastest turn both ways: none to the left
  EXPECT_NEAR(r.max_turn(0.2), 0.2, 1e-12);
  EXPECT_EQ(r.max_turn(0.15), 0.0);
  int turning = 0;
  for (double v = 0.0; v <= 0.5; v += 0.025) {
    for (double w = -1.0; w <= 1.0; w += 0.05) {
      const MotionCommand c = r.command_for({v, w});
      if (c.speed_m_s == 0.0) {
        EXPECT_EQ(c.turn_rad_s, 0.0);
        continue;
      }
      EXPECT_GE(c.speed_m_s, 0.1) << v << " " << w;
      EXPECT_LE(c.speed_m_s, 0.2) << v << " " << w;
      // Only the 0.2 m/s level turns, and only up to its usable 0.2 rad/s:
      // between speeds the slower level (no turns) caps it.
      EXPECT_LE(std::abs(c.turn_rad_s), r.max_turn(c.speed_m_s) + 1e-12) << v << " " << w;
      if (c.speed_m_s < 0.2) {
        EXPECT_EQ(c.turn_rad_s, 0.0) << v << " " << w;
      }
      turning += c.turn_rad_s != 0.0 ? 1 : 0;
    }
  }
  EXPECT_GT(turning, 0);  // it does turn where it can
}

// Speed-0 rows of a gait that turns on the spot: usable when it stays on
// the spot and turns as told; the herd turns only as fast as the usable
// rows reach from standing on both sides.
TEST(WalkResponse, TurnsOnTheSpotOnlyWhereTheSpeedZeroRowsAreUsable) {
  EXPECT_TRUE(calibration_usable(point(0.0, 0.1, 0.005, 0.095), 0.15));
  EXPECT_FALSE(calibration_usable(point(0.0, 0.1, 0.02, 0.1), 0.15));  // walks off
  EXPECT_FALSE(calibration_usable(point(0.0, 0.1, 0.0, -0.1), 0.15));  // wrong way
  EXPECT_FALSE(calibration_usable(point(0.0, 0.0, 0.0, 0.0), 0.15));   // standing is no turn
  GaitSteering s = steering();
  GaitCalibration cal = table();
  cal.points.push_back(point(0.0, -0.2, 0.0, -0.1));  // turns half as fast: unusable
  cal.points.push_back(point(0.0, -0.1, -0.005, -0.095));
  cal.points.push_back(point(0.0, 0.1, 0.004, 0.105));
  cal.points.push_back(point(0.0, 0.2, 0.006, 0.19));
  cal.points.push_back(point(0.0, 0.0, 0.0, 0.0));  // standing: no turn, ignored
  // Without turn_on_the_spot the rows are ignored: speed 0 stands.
  EXPECT_EQ(WalkResponse(s, &cal).spot_turn(), 0.0);
  EXPECT_EQ(WalkResponse(s, &cal).achieved({0.0, 0.1}), (MotionCommand{0.0, 0.0}));
  s.turn_on_the_spot = true;
  const WalkResponse r(s, &cal);
  EXPECT_DOUBLE_EQ(r.spot_turn(), 0.1);  // 0.2 to the left, 0.1 to the right
  const MotionCommand left = r.achieved({0.0, 0.1});
  EXPECT_DOUBLE_EQ(left.turn_rad_s, 0.105);
  EXPECT_DOUBLE_EQ(left.speed_m_s, 0.004);
  EXPECT_NEAR(r.achieved({0.0, -0.05}).turn_rad_s, -0.0475, 1e-12);  // halfway from standing
  EXPECT_DOUBLE_EQ(r.achieved({0.0, -0.3}).turn_rad_s, -0.095);      // within spot_turn()
  // The walking table is unchanged by them.
  EXPECT_EQ(r.min_speed(), 0.1);
  EXPECT_EQ(r.achieved({0.1, 0.0}), (MotionCommand{0.1, 0.0}));
  // Uncalibrated, it turns on the spot as told, within the fastest turn.
  EXPECT_EQ(WalkResponse(s).spot_turn(), 0.4);
  EXPECT_EQ(WalkResponse(s).achieved({0.0, -0.3}), (MotionCommand{0.0, -0.3}));
}

TEST(WalkResponse, LoadsTheGaitAndItsCalibration) {
  const std::string gait =
      "name: w\nstride_frequency_hz: 1\ncurves: {c: \"sin(2*PI*t)\"}\nlimbs: {l: 0, r: 0.5}\n"
      "joints: {a: {curve: c, limb: l}}\n";
  const auto dir = std::filesystem::temp_directory_path();
  const std::string plain = (dir / "plain.yaml").string();
  const std::string steer = (dir / "steer.yaml").string();
  std::filesystem::remove(calibration_path_for(steer));
  std::ofstream(plain) << gait;
  EXPECT_THROW(load_walk_response(plain), InputError);
  std::ofstream(steer) << gait
                       << "steering: {min_froude: 0.05, max_froude: 0.1, max_turn_dps: 10,"
                          " max_acceleration_m_s2: 0.2, hip_height_m: 0.2,"
                          " track_width_m: 0.2, sides: {left: [l], right: [r]}}\n";
  const WalkResponse uncalibrated = load_walk_response(steer);
  EXPECT_DOUBLE_EQ(uncalibrated.min_speed(), 0.05 * std::sqrt(9.81 * 0.2));
  // The table names the gait beside it and a model that exists.
  GaitCalibration beside = table();
  beside.gait_file = "steer.yaml";
  beside.model_file = "steer_model.xml";
  std::ofstream(dir / "steer_model.xml") << "<mujoco/>\n";
  write_gait_calibration(calibration_path_for(steer), beside);
  const WalkResponse calibrated = load_walk_response(steer);
  EXPECT_EQ(calibrated.min_speed(), 0.1);
  EXPECT_NEAR(calibrated.max_turn(0.1), deg_to_rad(10.0), 1e-12);  // capped by the steering
  // A table in which every walk fell leaves nothing to walk: refused at the
  // table, not later as a figure that "walks at most 0 m/s".
  GaitCalibration fallen = beside;
  for (CalibrationPoint& p : fallen.points) {
    p.fell = true;
    p.usable = false;
  }
  write_gait_calibration(calibration_path_for(steer), fallen);
  try {
    (void)load_walk_response(steer);
    ADD_FAILURE() << "a table without a usable walk loaded";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              calibration_path_for(steer) +
                  ": points: no speed whose straight walk is usable (every one fell or missed "
                  "the tolerance): calibrate the gait again (animrt gait calibrate)");
  }
  std::filesystem::remove(calibration_path_for(steer));
}

}  // namespace
}  // namespace animrt
