// Load-time evaluation of a motion over its whole length (robot_loader).

#include "animrt/runtime/motion_check.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/runtime/robot_loader.hpp"
#include "support/files.hpp"

namespace animrt {
namespace {

namespace fs = std::filesystem;

int line_of(const std::string& text, const std::string& what) {
  const auto at = text.find(what);
  return at == std::string::npos ? 0
                                 : static_cast<int>(std::count(
                                       text.begin(), text.begin() + static_cast<long>(at), '\n')) +
                                       1;
}

// The shipped quadruped and a copy of its walk whose hip curve is replaced.
class MotionCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("animrt_motion_check_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    robot_text_ = read_file(kSourceRoot + "/configs/robots/quadruped.yaml");
    write_file(robot(), robot_text_);
    write_file(dir_ / "models" / "quadruped.xml", "<!-- stand-in -->\n");
    gait_text_ = read_file(kSourceRoot + "/configs/gaits/walk.yaml");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string robot() const { return (dir_ / "robots" / "quadruped.yaml").string(); }
  std::string gait() const { return (dir_ / "robots" / ".." / "gaits" / "walk.yaml").string(); }

  void write_gait_with_hip(const std::string& expression) {
    std::string text = gait_text_;
    const auto from = text.find("  hip: \"");
    const auto to = text.find('\n', from);
    text.replace(from, to - from, "  hip: \"" + expression + "\"");
    write_file(dir_ / "gaits" / "walk.yaml", text);
    gait_text_ = text;
  }

  std::string error() {
    try {
      (void)load_robot(robot());
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }

  // "ROBOT:L:C: motion.file: joint NAME (GAIT:L:3: joints.NAME)"
  std::string prefix(const std::string& joint) const {
    return robot() + ":" + std::to_string(line_of(robot_text_, "  file: ../gaits/walk.yaml")) +
           ":9: motion.file: joint " + joint + " (" + gait() + ":" +
           std::to_string(line_of(gait_text_, "  " + joint + ":")) + ":3: joints." + joint + ")";
  }

  fs::path dir_;
  std::string robot_text_, gait_text_;
};

TEST_F(MotionCheckTest, ShippedWalkPasses) {
  write_file(dir_ / "gaits" / "walk.yaml", gait_text_);
  EXPECT_EQ(error(), "no error");
}

// A gait made with the balance reflex was scored with it, and the runtime
// plays the reflex on the trunk's IMU: a robot without one is refused at the
// gait's balance key, naming the robot file; with one it loads as a balanced
// gait that wants the figure's legs.
TEST_F(MotionCheckTest, AGaitWithTheBalanceReflexNeedsAnImu) {
  const std::string text = gait_text_ + "balance: {tilt_m: 0.3, tilt_rate_m_s: 0.1}\n";
  write_file(dir_ / "gaits" / "walk.yaml", text);
  const std::string e = error();
  EXPECT_NE(e.find(gait() + ":" + std::to_string(line_of(text, "balance:")) + ":"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("balance: this gait balances on the trunk's attitude, and " + robot() +
                   " has no IMU: give it one under imus:"),
            std::string::npos)
      << e;

  write_file(robot(), robot_text_ + "imus:\n  - {name: trunk, protocol: bno08x_rvc}\n");
  const LoadedRobot loaded = load_robot(robot());
  ASSERT_NE(loaded.balanced, nullptr);
  EXPECT_EQ(loaded.balanced, loaded.motion.get());
  EXPECT_FALSE(loaded.balanced->has_legs());
  EXPECT_EQ(loaded.balanced->gains().tilt_m, 0.3);
}

TEST_F(MotionCheckTest, NotFiniteLaterInTheRunIsRejected) {
  // Zero over the first stride (which the gait file's own check covers),
  // infinity minus infinity from about 1.34 strides on.
  write_gait_with_hip(
      "2.5 + 18.0*sin(1*2*PI*t) + 1e307*t*t*t*t*t*t*t*t*t*t - 1e307*t*t*t*t*t*t*t*t*t*t");
  const std::string message = error();
  // lh has no phase delay, so its hip is the first to get there.
  const std::string head = prefix("lh_hip") + " is not finite (NaN) at t = ";
  ASSERT_EQ(message.substr(0, head.size()), head) << message;
  const double t = std::stod(message.substr(head.size()));
  EXPECT_GT(t, 1.3);
  EXPECT_LT(t, 1.4);
  EXPECT_EQ(message.substr(message.size() - 2), " s");
}

TEST_F(MotionCheckTest, HugeButFiniteCurveLeavesTheLimits) {
  write_gait_with_hip("1e307*t*t - 1e307*t*t*t");
  // lf is delayed a quarter stride: at t = 0 its curve time is -0.25.
  EXPECT_EQ(error(), prefix("lf_hip") +
                         " reaches 7.8125e+305 deg at t = 0 s, outside its limits -45..45 deg by "
                         "more than the 4.5 deg margin");
}

TEST_F(MotionCheckTest, AMillionDegreesIsRejected) {
  write_gait_with_hip("1e6");
  EXPECT_EQ(error(), prefix("lf_hip") +
                         " reaches 1e+06 deg at t = 0 s, outside its limits -45..45 deg by more "
                         "than the 4.5 deg margin");
}

TEST_F(MotionCheckTest, WithinTheMarginPassesBeyondItFails) {
  // Hip limits are -45..45 deg; the margin is 5 % of 90 deg.
  write_gait_with_hip("49.4 + 0*t");
  EXPECT_EQ(error(), "no error");
  write_gait_with_hip("49.6 + 0*t");
  EXPECT_EQ(error(), prefix("lf_hip") +
                         " reaches 49.6 deg at t = 0 s, outside its limits -45..45 deg by more "
                         "than the 4.5 deg margin");
}

TEST_F(MotionCheckTest, FirstPoseTheStartRampCannotReachInTime) {
  // 40 deg from home at 3000 deg/s^2: the ramp needs 1.1 * sqrt(5.7735 * 40 / 3000) s
  // (more than the 1.1 * 1.875 * 40 / 300 s its velocity limit asks).
  write_gait_with_hip("40 + 0*t");
  std::string text = robot_text_;
  text.replace(text.find("  start_ramp_s: 2.0"), 19,
               "  start_ramp_s: 0.1\n  start_ramp_max_s: 0.2");
  robot_text_ = text;
  write_file(robot(), text);
  EXPECT_EQ(error(),
            robot() + ":" + std::to_string(line_of(text, "  file: ../gaits/walk.yaml")) +
                ":9: motion.file: the start ramp from the home pose to the first pose "
                "takes 0.305198 s, longer than safety.start_ramp_max_s (0.2 s); joint lf_hip "
                "(" +
                gait() + ":" + std::to_string(line_of(gait_text_, "  lf_hip:")) +
                ":3: joints.lf_hip) starts at 40 deg, home 0 deg");
}

TEST(MotionCheck, MarginIsTwoDegreesOrFivePercent) {
  JointSpec narrow;
  narrow.limits.min_position = deg_to_rad(-10);
  narrow.limits.max_position = deg_to_rad(10);
  EXPECT_DOUBLE_EQ(limit_margin(narrow), deg_to_rad(2.0));
  JointSpec wide = narrow;
  wide.limits.max_position = deg_to_rad(190);
  EXPECT_DOUBLE_EQ(limit_margin(wide), 0.05 * deg_to_rad(200));
  JointSpec slide;
  slide.type = JointType::prismatic;
  slide.limits.min_position = 0.0;
  slide.limits.max_position = 0.01;
  EXPECT_DOUBLE_EQ(limit_margin(slide), 0.002);
}

TEST(MotionCheck, GaitIsCheckedOverTwentyStridesBetweenOneAndTenMinutes) {
  EXPECT_DOUBLE_EQ(gait_check_duration(1.0), 60.0);
  EXPECT_DOUBLE_EQ(gait_check_duration(0.1), 200.0);
  EXPECT_DOUBLE_EQ(gait_check_duration(0.01), 600.0);
}

}  // namespace
}  // namespace animrt
