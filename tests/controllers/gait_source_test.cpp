#include "animrt/controllers/gait/gait_source.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "animrt/core/joint.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

// More time than any wind-down asks for: the stop deadline does not cut it.
constexpr double kGaitAmpleS = 100.0;

const char* const kGait = R"yaml(name: test
stride_frequency_hz: 2.0
curves:
  lin: "t"
  wave: "10 + 5*sin(2*PI*t)"
limbs:
  a: 0.0
  b: 0.25
joints:
  j1: {curve: wave, limb: a}
  j2: {curve: wave, limb: b, sign: -1, scale: 2.0, offset_deg: 3}
  j3: {curve: lin, limb: b, scale: 0.5, offset_deg: -1}
)yaml";

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::vector<JointSpec> robot(std::initializer_list<const char*> names) {
  std::vector<JointSpec> joints;
  for (const char* n : names) {
    JointSpec j;
    j.name = n;
    j.limits = {-1.0, 1.0, 5.0, 50.0};
    joints.push_back(j);
  }
  return joints;
}

class GaitSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = write_temp("gait_source_test.yaml", kGait);
    joints_ = robot({"x", "j2", "j1", "j3", "y"});
    source_ = load_gait_source(path_, joints_);
  }

  // Targets in degrees at t seconds; unmapped joints keep 99 rad.
  std::vector<double> sample_deg(double t) const {
    std::vector<double> targets(joints_.size(), 99.0);
    source_->sample(t, targets);
    for (std::size_t i = 0; i < targets.size(); ++i) {
      if (targets[i] != 99.0) targets[i] = rad_to_deg(targets[i]);
    }
    return targets;
  }

  std::string path_;
  std::vector<JointSpec> joints_;
  std::unique_ptr<MotionSource> source_;
};

TEST_F(GaitSourceTest, DrivesTheMappedJointsInFileOrder) {
  const auto driven = source_->driven_joints();
  EXPECT_EQ(std::vector<int>(driven.begin(), driven.end()), (std::vector<int>{2, 1, 3}));
}

// Hand-computed with f = 2 Hz: u = 2 t - phase; wave(u) = 10 + 5 sin(2 pi u).
//   j1 = wave(u_a)                 j2 = -1 * 2 * wave(u_b) + 3
//   j3 = 0.5 * u_b - 1
TEST_F(GaitSourceTest, SamplesHandComputedValues) {
  struct Row {
    double t, j1, j2, j3;
  };
  const Row rows[] = {
      // t = 0: u_a = 0, u_b = -0.25 (sin = -1, wave = 5).
      {0.0, 10.0, -7.0, -1.125},
      // t = 0.125: u_a = 0.25 (wave 15), u_b = 0 (wave 10).
      {0.125, 15.0, -17.0, -1.0},
      // t = 0.25: u_a = 0.5 (wave 10), u_b = 0.25 (wave 15).
      {0.25, 10.0, -27.0, -0.875},
      // t = 0.5: u_a = 1 (wave 10), u_b = 0.75 (wave 5).
      {0.5, 10.0, -7.0, -0.625},
  };
  for (const Row& r : rows) {
    const auto deg = sample_deg(r.t);
    EXPECT_NEAR(deg[2], r.j1, 1e-9) << "j1 at t = " << r.t;
    EXPECT_NEAR(deg[1], r.j2, 1e-9) << "j2 at t = " << r.t;
    EXPECT_NEAR(deg[3], r.j3, 1e-9) << "j3 at t = " << r.t;
    EXPECT_EQ(deg[0], 99.0);  // not driven: untouched
    EXPECT_EQ(deg[4], 99.0);
  }
}

TEST_F(GaitSourceTest, TargetsAreRadians) {
  std::vector<double> targets(joints_.size(), 0.0);
  source_->sample(0.125, targets);
  EXPECT_NEAR(targets[2], 15.0 * kPi / 180.0, 1e-15);
}

// At a stop the walk winds down over two strides (1 s at 2 Hz): it starts
// where the walk is, keeps stepping with an ever smaller swing, and stands
// in each curve's stride mean (wave: 10) once the time it asked is over.
TEST_F(GaitSourceTest, AWindDownEasesTheSwingToTheStrideMeanOverTwoStrides) {
  const auto walking = sample_deg(1.1);
  EXPECT_DOUBLE_EQ(source_->wind_down(1.1, kGaitAmpleS), 1.0);
  const auto at_request = sample_deg(1.1);
  EXPECT_DOUBLE_EQ(at_request[2], walking[2]);
  double first_stride = 0.0, second_stride = 0.0;
  for (double t = 1.1; t < 2.1; t += 0.005) {
    const double swing = std::abs(sample_deg(t)[2] - 10.0);
    (t < 1.6 ? first_stride : second_stride) =
        std::max(t < 1.6 ? first_stride : second_stride, swing);
  }
  EXPECT_GT(first_stride, 3.0);
  EXPECT_LT(second_stride, first_stride);
  for (double t = 2.1; t < 3.0; t += 0.05) {
    const auto deg = sample_deg(t);
    EXPECT_NEAR(deg[2], 10.0, 1e-9) << t;
    EXPECT_NEAR(deg[1], -17.0, 1e-9) << t;
  }
}

// A stop that grants less than two strides (here 0.3 s of the 1 s) gets a
// shorter wind-down, not a cut one: the swing and the cadence ease out
// over the time granted, and the figure stands in the stride means when
// it is up, for the ramp home to start from a stand.
TEST_F(GaitSourceTest, AWindDownGrantedLessThanTwoStridesStandsWhenTheGrantedTimeIsUp) {
  const auto walking = sample_deg(1.1);
  EXPECT_DOUBLE_EQ(source_->wind_down(1.1, 0.3), 0.3);
  EXPECT_DOUBLE_EQ(sample_deg(1.1)[2], walking[2]);
  double swing = 0.0;
  for (double t = 1.1; t < 1.25; t += 0.005)
    swing = std::max(swing, std::abs(sample_deg(t)[2] - 10.0));
  EXPECT_GT(swing, 1.0);  // it kept stepping at first
  for (double t = 1.4; t < 2.5; t += 0.01) {
    const auto deg = sample_deg(t);
    EXPECT_NEAR(deg[2], 10.0, 1e-9) << t;
    EXPECT_NEAR(deg[1], -17.0, 1e-9) << t;
  }
  // Its speed eases to nothing too: no jump from the last step to the stand.
  EXPECT_NEAR(sample_deg(1.399)[2], 10.0, 1e-3);
}

// Nothing granted: the walk is left as it is, for the ramp home at once.
TEST_F(GaitSourceTest, AWindDownGrantedNoTimeAsksForNone) {
  const auto walking = sample_deg(1.3);
  EXPECT_EQ(source_->wind_down(1.1, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(sample_deg(1.3)[2], walking[2]);
}

// A gait that does not walk (an animatronic's sway) has nothing to wind
// down: a stop ramps it home at once, and it plays on as before until then.
TEST(GaitSource, AGaitThatDoesNotWalkAsksForNoWindDown) {
  std::string text = kGait;
  text.replace(text.find("curves:"), 0, "walks: false\n");
  const auto joints = robot({"x", "j2", "j1", "j3", "y"});
  const auto sway = load_gait_source(write_temp("sway.yaml", text), joints);
  const auto walk = load_gait_source(write_temp("walk.yaml", kGait), joints);
  EXPECT_EQ(sway->wind_down(1.1, kGaitAmpleS), 0.0);
  EXPECT_DOUBLE_EQ(walk->wind_down(1.1, kGaitAmpleS), 1.0);
  std::vector<double> a(joints.size(), 0.0), b(joints.size(), 0.0);
  sway->sample(1.3, a);
  load_gait_source(write_temp("walk2.yaml", kGait), joints)->sample(1.3, b);
  EXPECT_EQ(a, b);
}

TEST_F(GaitSourceTest, SampleDoesNotAllocate) {
  std::vector<double> targets(joints_.size(), 0.0);
  test::AllocationCounter counter;
  for (int i = 0; i < 1000; ++i) source_->sample(i * 0.005, targets);
  EXPECT_EQ(counter.count(), 0);
}

TEST(GaitSource, JointNotInTheRobot) {
  const std::string path = write_temp("gait_source_missing_joint.yaml", kGait);
  try {
    (void)load_gait_source(path, robot({"x", "j2", "j1", "y"}));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        path + ":12:3: joints.j3: no joint named 'j3' in the robot (its joints: x, j2, j1, y)");
  }
}

TEST(GaitSource, FileErrorsPassThrough) {
  const std::string path = write_temp("gait_source_bad.yaml", std::string(kGait) + "extra: 1\n");
  try {
    (void)load_gait_source(path, robot({"j1", "j2", "j3"}));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().line, 13);
    EXPECT_EQ(e.key(), "extra");
  }
}

TEST(GaitSource, FromAGaitInMemory) {
  GaitFile g;
  g.name = "evolved";
  g.froude = FroudeTiming{1.0, 1.0};  // f = sqrt(9.81) / 2.3
  g.curves.push_back({"c", "t", {}});
  g.limbs.push_back({"l", 0.5, {}});
  g.joints.push_back({"q", "c", "l", 1, 1.0, 0.0, {}});
  const auto joints = robot({"q"});
  const auto source = make_gait_source(g, joints);
  std::vector<double> targets(1, 0.0);
  source->sample(2.3, targets);
  EXPECT_NEAR(rad_to_deg(targets[0]), 3.1320919526732 - 0.5, 1e-9);

  g.joints[0].name = "p";
  try {
    (void)make_gait_source(g, joints);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "<input>: joints.p: no joint named 'p' in the robot (its joints: q)");
  }
  g.joints[0].curve = "d";
  try {
    (void)make_gait_source(g, joints);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "<input>: joints.p.curve: undefined curve 'd' (curves: c)");
  }
}

}  // namespace
}  // namespace animrt
