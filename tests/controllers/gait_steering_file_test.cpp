// The steering section of a gait file: reading, strict errors, round trip.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/core/joint.hpp"
#include "controllers/gait_file_error.hpp"

namespace animrt {
namespace {

const std::string kHead =
    "name: s\n"                         // 1
    "stride_frequency_hz: 1.0\n"        // 2
    "curves: {hip: \"sin(2*PI*t)\"}\n"  // 3
    "limbs: {lf: 0, rf: 0.5}\n"         // 4
    "joints:\n"                         // 5
    "  a: {curve: hip, limb: lf}\n"     // 6
    "  b: {curve: hip, limb: rf}\n"     // 7
    "  yaw: {curve: hip, limb: lf}\n";  // 8

std::string steering(const std::string& body) { return kHead + "steering:\n" + body; }  // 9

const std::string kGood =
    "  min_froude: 0.05\n"                  // 10
    "  max_froude: 0.1\n"                   // 11
    "  max_turn_dps: 30\n"                  // 12
    "  max_acceleration_m_s2: 0.3\n"        // 13
    "  hip_height_m: 0.2\n"                 // 14
    "  track_width_m: 0.15\n"               // 15
    "  sides: {left: [lf], right: [rf]}\n"  // 16
    "  yaw_joints: [yaw]\n";                // 17

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(GaitSteeringFile, ReadsTheSection) {
  const GaitFile g = parse_gait_file(steering(kGood), "g.yaml");
  ASSERT_TRUE(g.steering.has_value());
  const GaitSteering& s = *g.steering;
  EXPECT_EQ(s.min_froude, 0.05);
  EXPECT_EQ(s.max_froude, 0.1);
  EXPECT_DOUBLE_EQ(s.max_turn_rad_s, 30.0 * kPi / 180.0);
  EXPECT_EQ(s.max_acceleration_m_s2, 0.3);
  EXPECT_EQ(s.hip_height_m, 0.2);
  EXPECT_EQ(s.track_width_m, 0.15);
  EXPECT_EQ(s.left, std::vector<std::string>{"lf"});
  EXPECT_EQ(s.right, std::vector<std::string>{"rf"});
  EXPECT_EQ(s.yaw_joints, std::vector<std::string>{"yaw"});
  EXPECT_NEAR(s.min_speed_m_s(), 0.05 * std::sqrt(9.81 * 0.2), 1e-12);
  EXPECT_FALSE(parse_gait_file(kHead, "g.yaml").steering.has_value());
}

TEST(GaitSteeringFile, HipHeightDefaultsToTheFroudeTiming) {
  std::string text = replace(steering(kGood), "  hip_height_m: 0.2\n", "");
  text = replace(text, "stride_frequency_hz: 1.0", "froude: {number: 0.07, hip_height_m: 0.3}");
  EXPECT_EQ(parse_gait_file(text, "g.yaml").steering->hip_height_m, 0.3);
}

TEST(GaitSteeringFile, ErrorsNameFileLineAndKey) {
  const std::string good = steering(kGood);
  EXPECT_EQ(gait_file_error(replace(good, "max_froude: 0.1", "max_froude: 0.01")),
            "g.yaml:11:15: steering.max_froude: max_froude (0.01) is below min_froude (0.05)");
  // Required with stride_frequency_hz; reported at the section.
  EXPECT_EQ(gait_file_error(replace(good, "  hip_height_m: 0.2\n", "")),
            "g.yaml:10:3: steering.hip_height_m: required key is missing");
  const std::string unknown =
      gait_file_error(replace(good, "  track_width_m", "  speed: 1\n  track_width_m"));
  EXPECT_NE(unknown.find("g.yaml:15:3: steering.speed"), std::string::npos) << unknown;
  const std::string limb = gait_file_error(replace(good, "left: [lf]", "left: [xx]"));
  EXPECT_NE(limb.find("g.yaml:16:18: steering.sides.left"), std::string::npos) << limb;
  EXPECT_NE(limb.find("undefined limb 'xx'"), std::string::npos) << limb;
  const std::string both = gait_file_error(replace(good, "right: [rf]", "right: [rf, lf]"));
  EXPECT_NE(both.find("g.yaml:16:"), std::string::npos) << both;
  EXPECT_NE(both.find("on both sides"), std::string::npos) << both;
  const std::string yaw = gait_file_error(replace(good, "[yaw]", "[neck]"));
  EXPECT_NE(yaw.find("g.yaml:17:"), std::string::npos) << yaw;
  EXPECT_NE(yaw.find("steering.yaw_joints"), std::string::npos) << yaw;
  const std::string turn = gait_file_error(replace(good, "max_turn_dps: 30", "max_turn_dps: -5"));
  EXPECT_NE(turn.find("g.yaml:12:17: steering.max_turn_dps"), std::string::npos) << turn;
  const std::string acc = gait_file_error(replace(good, "0.3\n", "0\n"));
  EXPECT_NE(acc.find("g.yaml:13:26: steering.max_acceleration_m_s2"), std::string::npos) << acc;
}

TEST(GaitSteeringFile, RoundTripsThroughTheWriter) {
  GaitFile g = parse_gait_file(steering(kGood), "g.yaml");
  g.steering->max_turn_rad_s = 0.123456789;  // not a round number of degrees
  const GaitFile back = parse_gait_file(format_gait_file(g), "back.yaml");
  EXPECT_EQ(back, g);
  ASSERT_TRUE(back.steering.has_value());
  EXPECT_EQ(back.steering->max_turn_rad_s, 0.123456789);
  GaitFile other = g;
  other.steering->right = {"lf"};
  other.steering->left = {"rf"};
  EXPECT_FALSE(other == g);
}

TEST(GaitSteeringFile, TurnOnTheSpotAndItsTrackAndOffset) {
  const GaitFile plain = parse_gait_file(steering(kGood + "  swing_offset: -0.4\n"), "g.yaml");
  EXPECT_FALSE(plain.steering->turn_on_the_spot);
  EXPECT_EQ(plain.steering->spot_track_width_m, plain.steering->track_width_m);
  EXPECT_EQ(plain.steering->spot_swing_offset, -0.4);  // the walk's, unless given
  const std::string extra =
      "  turn_on_the_spot: true\n"    // 18
      "  spot_track_width_m: 0.8\n"   // 19
      "  spot_swing_offset: -0.2\n";  // 20
  const GaitFile g = parse_gait_file(steering(kGood + extra), "g.yaml");
  EXPECT_TRUE(g.steering->turn_on_the_spot);
  EXPECT_EQ(g.steering->spot_track_width_m, 0.8);
  EXPECT_EQ(g.steering->spot_swing_offset, -0.2);
  EXPECT_EQ(parse_gait_file(format_gait_file(g), "back.yaml"), g);
  GaitFile other = g;
  other.steering->turn_on_the_spot = false;
  EXPECT_FALSE(other == g);
  const std::string flag = gait_file_error(steering(kGood + "  turn_on_the_spot: 3\n"));
  EXPECT_NE(flag.find("g.yaml:18:21: steering.turn_on_the_spot"), std::string::npos) << flag;
  const std::string track = gait_file_error(steering(kGood + "  spot_track_width_m: 0\n"));
  EXPECT_NE(track.find("g.yaml:18:23: steering.spot_track_width_m"), std::string::npos) << track;
  const std::string off = gait_file_error(steering(kGood + "  spot_swing_offset: 2\n"));
  EXPECT_NE(off.find("g.yaml:18:22: steering.spot_swing_offset"), std::string::npos) << off;
}

TEST(GaitSteeringFile, LiftCurvesSwingOffsetAndFixedCadence) {
  const GaitFile plain = parse_gait_file(steering(kGood), "g.yaml");
  EXPECT_TRUE(plain.steering->lift_curves.empty());
  EXPECT_EQ(plain.steering->swing_offset, 0.0);
  EXPECT_FALSE(plain.steering->fixed_cadence);
  const std::string extra =
      "  lift_curves: [hip]\n"    // 18
      "  swing_offset: -0.4\n"    // 19
      "  fixed_cadence: true\n";  // 20
  const GaitFile g = parse_gait_file(steering(kGood + extra), "g.yaml");
  EXPECT_EQ(g.steering->lift_curves, std::vector<std::string>{"hip"});
  EXPECT_EQ(g.steering->swing_offset, -0.4);
  EXPECT_TRUE(g.steering->fixed_cadence);
  const GaitFile back = parse_gait_file(format_gait_file(g), "back.yaml");
  EXPECT_EQ(back, g);
  GaitFile other = g;
  other.steering->fixed_cadence = false;
  EXPECT_FALSE(other == g);
  other = g;
  other.steering->swing_offset = 0.1;
  EXPECT_FALSE(other == g);

  const std::string curve = gait_file_error(steering(kGood + "  lift_curves: [knee]\n"));
  EXPECT_NE(curve.find("g.yaml:18:17: steering.lift_curves"), std::string::npos) << curve;
  EXPECT_NE(curve.find("undefined curve 'knee'"), std::string::npos) << curve;
  const std::string offset = gait_file_error(steering(kGood + "  swing_offset: 0.95\n"));
  EXPECT_NE(offset.find("g.yaml:18:17: steering.swing_offset"), std::string::npos) << offset;
  const std::string cadence = gait_file_error(steering(kGood + "  fixed_cadence: 2\n"));
  EXPECT_NE(cadence.find("g.yaml:18:18: steering.fixed_cadence"), std::string::npos) << cadence;
  GaitFile bad = g;
  bad.steering->spot_swing_offset = 1.0;
  EXPECT_THROW(validate_gait(bad), InputError);
  bad = g;
  bad.steering->lift_curves = {"nope"};
  EXPECT_THROW(validate_gait(bad), InputError);
  bad = g;
  bad.steering->swing_offset = 1.0;
  EXPECT_THROW(validate_gait(bad), InputError);
}

TEST(GaitSteeringFile, ValidateChecksASteeringBuiltInMemory) {
  GaitFile g = parse_gait_file(steering(kGood), "g.yaml");
  g.steering->left = {"nope"};
  EXPECT_THROW(validate_gait(g), InputError);
  g = parse_gait_file(steering(kGood), "g.yaml");
  g.steering->track_width_m = 0.0;
  EXPECT_THROW(validate_gait(g), InputError);
}

}  // namespace
}  // namespace animrt
