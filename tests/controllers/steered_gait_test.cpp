// Steered playback of a gait: phase continuity, turning, standing,
// acceleration limit, clamping, no allocation.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "animrt/controllers/gait/froude.hpp"
#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/gait/steered_gait_source.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

// More time than any wind-down asks for: the stop deadline does not cut it.
constexpr double kSteeredAmpleS = 100.0;

constexpr double kDt = 0.005;  // the quadruped's 200 Hz cycle
constexpr double kMeanDeg = 10.0;
constexpr double kSwingDeg = 20.0;

const char* const kSteeredGait = R"yaml(name: steer
stride_frequency_hz: 1.0
curves:
  hip: "10 + 20*sin(2*PI*t)"
limbs: {lf: 0, rf: 0.5, lh: 0.5, rh: 0}
joints:
  lf_hip: {curve: hip, limb: lf}
  rf_hip: {curve: hip, limb: rf}
  lh_hip: {curve: hip, limb: lh}
  rh_hip: {curve: hip, limb: rh}
steering:
  min_froude: 0.03
  max_froude: 0.12
  max_turn_dps: 30
  max_acceleration_m_s2: 0.2
  hip_height_m: 0.2
  track_width_m: 0.2
  sides: {left: [lf, lh], right: [rf, rh]}
)yaml";

std::vector<JointSpec> specs() {
  std::vector<JointSpec> out;
  for (const char* n : {"lf_hip", "rf_hip", "lh_hip", "rh_hip"}) {
    JointSpec s;
    s.name = n;
    s.limits = {-kPi, kPi, 100.0, 10000.0};
    out.push_back(s);
  }
  return out;
}

struct Rig {
  GaitFile gait = parse_gait_file(kSteeredGait, "steer.yaml");
  std::vector<JointSpec> joints = specs();
  std::unique_ptr<MotionSource> source = make_gait_source(gait, joints);
  SteeredGaitSource& steered = dynamic_cast<SteeredGaitSource&>(*source);
  std::vector<double> targets = std::vector<double>(4, 0.0);
  double t = 0.0;
  const GaitSteering& st() const { return *gait.steering; }

  // Samples for `seconds`, returning the largest and smallest target (deg)
  // of each joint over that time.
  std::vector<std::pair<double, double>> run(double seconds) {
    std::vector<std::pair<double, double>> range(4, {1e9, -1e9});
    const long steps = std::lround(seconds / kDt);
    for (long k = 0; k < steps; ++k) {
      source->sample(t, targets);
      t += kDt;
      for (std::size_t j = 0; j < 4; ++j) {
        const double deg = rad_to_deg(targets[j]);
        range[j] = {std::min(range[j].first, deg), std::max(range[j].second, deg)};
      }
    }
    return range;
  }
};

double swing(const std::pair<double, double>& r) { return r.second - r.first; }

TEST(SteeredGait, PhaseIsContinuousAcrossAFrequencyStep) {
  Rig rig;
  const double lo = rig.st().min_speed_m_s(), hi = rig.st().max_speed_m_s();
  rig.source->steer({lo, 0.0});
  rig.run(3.0);
  rig.source->steer({hi, 0.0});
  // Fastest possible joint speed at the fastest stride: swing x 2 pi f x
  // the largest amplitude scale.
  const double h = rig.st().hip_height_m;
  const double native_fr = froude_for_stride_frequency(1.0, h);
  const double scale =
      froude_stride_length(rig.st().max_froude, h) / froude_stride_length(native_fr, h);
  const double f_max = froude_stride_frequency(rig.st().max_froude, h);
  const double bound = deg_to_rad(kSwingDeg * scale * 2.0 * kPi * f_max) * kDt * 1.1;
  std::vector<double> prev(4);
  rig.source->sample(rig.t, prev);
  double worst = 0.0;
  for (int k = 0; k < 1200; ++k) {
    rig.t += kDt;
    rig.source->sample(rig.t, rig.targets);
    for (std::size_t j = 0; j < 4; ++j) worst = std::max(worst, std::abs(rig.targets[j] - prev[j]));
    prev = rig.targets;
  }
  EXPECT_LT(worst, bound);
  EXPECT_GT(worst, 0.2 * bound);  // it does walk
}

TEST(SteeredGait, TurnShortensTheInnerSideStrides) {
  Rig rig;
  const double v = 0.5 * (rig.st().min_speed_m_s() + rig.st().max_speed_m_s());
  const double w = rig.st().max_turn_rad_s;
  rig.source->steer({v, w});  // to the left: left side inside
  rig.run(4.0);
  const auto range = rig.run(3.0);
  const double inner = swing(range[0]), outer = swing(range[1]);
  EXPECT_LT(inner, outer);
  const double half = 0.5 * rig.st().track_width_m;
  EXPECT_NEAR(inner / outer, (v - w * half) / (v + w * half), 0.02);
  EXPECT_NEAR(swing(range[2]), inner, 0.05);  // lh: left too
  // And the other way.
  rig.source->steer({v, -w});
  rig.run(4.0);
  const auto back = rig.run(3.0);
  EXPECT_GT(swing(back[0]), swing(back[1]));
}

TEST(SteeredGait, ZeroSpeedStandsInTheMeanPoseAndStays) {
  Rig rig;
  rig.source->steer({rig.st().max_speed_m_s(), 0.0});
  const auto walking = rig.run(2.0);
  EXPECT_GT(swing(walking[0]), 10.0);
  rig.source->steer({0.0, 0.0});
  rig.run(3.0);
  const auto standing = rig.run(2.0);
  for (const auto& r : standing) {
    EXPECT_NEAR(r.first, kMeanDeg, 1e-9);
    EXPECT_NEAR(r.second, kMeanDeg, 1e-9);
  }
  EXPECT_EQ(rig.steered.current().speed_m_s, 0.0);
  // Below the slowest speed stands as well; a new command walks again.
  rig.source->steer({0.5 * rig.st().min_speed_m_s(), 0.0});
  EXPECT_LT(swing(rig.run(2.0)[0]), 1e-9);
  rig.source->steer({rig.st().min_speed_m_s(), 0.0});
  rig.run(3.0);
  EXPECT_GT(swing(rig.run(2.0)[0]), 5.0);
}

// A stop winds the walk down: the source stands as on a command under the
// slowest speed, within the time it says, and takes no steering back into
// the walk from the cycle (the cycle holds it back).
TEST(SteeredGait, AWindDownStandsInTheMeanPoseWithinTheTimeItAsks) {
  Rig rig;
  rig.source->steer({rig.st().max_speed_m_s(), 0.0});
  rig.run(2.0);
  const double asked = rig.source->wind_down(rig.t, kSteeredAmpleS);
  EXPECT_GT(asked, 0.5);
  EXPECT_LE(asked, 1.0 / rig.st().min_speed_m_s() + 10.0);
  const auto winding = rig.run(asked + kDt);  // to the first cycle at or past it
  EXPECT_GT(swing(winding[0]), 1.0);          // it kept stepping
  const auto after = rig.run(1.0);
  for (const auto& r : after) {
    EXPECT_NEAR(r.first, kMeanDeg, 1e-9);
    EXPECT_NEAR(r.second, kMeanDeg, 1e-9);
  }
  EXPECT_EQ(rig.steered.current().speed_m_s, 0.0);
}

TEST(SteeredGait, SpeedRampsAtTheAccelerationLimit) {
  Rig rig;
  const double lo = rig.st().min_speed_m_s(), hi = rig.st().max_speed_m_s();
  const double a = rig.st().max_acceleration_m_s2;
  rig.source->steer({lo, 0.0});
  rig.run(1.0);
  ASSERT_NEAR(rig.steered.current().speed_m_s, lo, 1e-12);
  rig.source->steer({hi, 0.0});
  double prev = rig.steered.current().speed_m_s;
  double reached = -1.0;
  const double start = rig.t;
  for (int k = 0; k < 2000 && reached < 0; ++k) {
    rig.run(kDt);
    const double v = rig.steered.current().speed_m_s;
    EXPECT_LE(v - prev, a * kDt + 1e-12);
    prev = v;
    if (v >= hi - 1e-12) reached = rig.t - start;
  }
  ASSERT_GT(reached, 0.0);
  EXPECT_GE(reached, (hi - lo) / a - 2 * kDt);
  EXPECT_LE(reached, (hi - lo) / a + 2 * kDt);
}

TEST(SteeredGait, CommandsAreClampedToTheSteeringLimits) {
  Rig rig;
  rig.source->steer({100.0, 100.0});
  EXPECT_EQ(rig.steered.target().speed_m_s, rig.st().max_speed_m_s());
  EXPECT_EQ(rig.steered.target().turn_rad_s, rig.st().max_turn_rad_s);
  rig.source->steer({0.1, -100.0});
  EXPECT_EQ(rig.steered.target().turn_rad_s, -rig.st().max_turn_rad_s);
  rig.source->steer({std::nan(""), std::nan("")});
  EXPECT_EQ(rig.steered.target().speed_m_s, 0.0);
  EXPECT_EQ(rig.steered.target().turn_rad_s, 0.0);
  rig.source->steer({-1.0, 0.0});
  EXPECT_EQ(rig.steered.target().speed_m_s, 0.0);
}

TEST(SteeredGait, RestartsWhenTimeGoesBack) {
  Rig rig;
  std::vector<double> first(4), again(4);
  rig.source->sample(0.0, first);
  rig.run(2.5);
  rig.source->sample(0.0, again);
  EXPECT_EQ(first, again);
}

TEST(SteeredGait, WithoutASteeringSectionCommandsAreIgnored) {
  GaitFile gait = parse_gait_file(kSteeredGait, "steer.yaml");
  gait.steering.reset();
  const auto joints = specs();
  auto a = make_gait_source(gait, joints);
  auto b = make_gait_source(gait, joints);
  b->steer({0.0, 1.0});
  std::vector<double> ta(4), tb(4);
  for (int k = 0; k < 400; ++k) {
    a->sample(k * kDt, ta);
    b->sample(k * kDt, tb);
    ASSERT_EQ(ta, tb);
  }
  b->sample(0.25, tb);
  EXPECT_NEAR(rad_to_deg(tb[0]), kMeanDeg + kSwingDeg, 1e-9);  // plays as the file says
}

TEST(SteeredGait, UncommandedPlaysTheGaitsOwnTiming) {
  Rig rig;
  // Native speed of 1 Hz at h = 0.2 is inside the range: amplitude scale 1.
  std::vector<double> tg(4);
  rig.source->sample(0.0, tg);
  for (int k = 1; k <= 50; ++k) rig.source->sample(k * kDt, tg);  // t = 0.25 s
  EXPECT_NEAR(rad_to_deg(tg[0]), kMeanDeg + kSwingDeg, 1e-6);
}

// kSteeredGait with extra lines under `joints` and `steering`, and robot joints for
// every joint it maps (the four hips first).
struct ExtendedRig {
  GaitFile gait;
  std::vector<JointSpec> joints = specs();
  std::unique_ptr<MotionSource> source;
  std::vector<double> targets;
  double t = 0.0;
  ExtendedRig(const std::string& curves, const std::string& more_joints,
              const std::vector<std::string>& names, const std::string& more_steering) {
    std::string text = kSteeredGait;
    const std::string curve_at = "  hip: \"10 + 20*sin(2*PI*t)\"";
    text.replace(text.find(curve_at), curve_at.size(), curve_at + curves);
    const std::string last = "  rh_hip: {curve: hip, limb: rh}";
    text.replace(text.find(last), last.size(), last + more_joints);
    text += more_steering;
    gait = parse_gait_file(text, "extended.yaml");
    for (const std::string& n : names) {
      JointSpec j;
      j.name = n;
      j.limits = {-kPi, kPi, 100.0, 10000.0};
      joints.push_back(j);
    }
    source = make_gait_source(gait, joints);
    targets.assign(joints.size(), 0.0);
  }
  const GaitSteering& st() const { return *gait.steering; }
  // Steers, settles 4 s, then samples 3 s: per joint the lowest, highest and
  // mean target (deg), and the sum of joint j's target times lf_hip's
  // deviation from its mean (positive: in phase with the hip).
  struct Stats {
    std::vector<double> lo, hi, mean, corr;
  };
  Stats under(MotionCommand command) {
    source->steer(command);
    for (int k = 0; k < 800; ++k, t += kDt) source->sample(t, targets);
    const std::size_t n = targets.size();
    Stats out{std::vector<double>(n, 1e9), std::vector<double>(n, -1e9), std::vector<double>(n),
              std::vector<double>(n)};
    constexpr int kSteps = 600;
    for (int k = 0; k < kSteps; ++k, t += kDt) {
      source->sample(t, targets);
      const double hip = rad_to_deg(targets[0]) - kMeanDeg;
      for (std::size_t j = 0; j < n; ++j) {
        const double d = rad_to_deg(targets[j]);
        out.lo[j] = std::min(out.lo[j], d);
        out.hi[j] = std::max(out.hi[j], d);
        out.mean[j] += d / kSteps;
        out.corr[j] += d * hip;
      }
    }
    return out;
  }
};

TEST(SteeredGait, YawJointsSwingWithTheTurn) {
  ExtendedRig rig("", "\n  yaw: {curve: hip, limb: lf}", {"yaw"}, "  yaw_joints: [yaw]\n");
  const double lo = rig.st().min_speed_m_s(), hi = rig.st().max_speed_m_s();
  const double w = rig.st().max_turn_rad_s;
  const auto straight = rig.under({lo, 0.0});
  EXPECT_EQ(straight.lo[4], 0.0);  // at its offset (home) when walking straight
  EXPECT_EQ(straight.hi[4], 0.0);
  // At the fastest turn at the slowest walk: the whole curve, 10 +- 20 deg,
  // in phase with it.
  const auto left = rig.under({lo, w});
  EXPECT_NEAR(left.hi[4] - left.lo[4], 2.0 * kSwingDeg, 0.5);
  EXPECT_NEAR(0.5 * (left.hi[4] + left.lo[4]), kMeanDeg, 0.5);
  EXPECT_GT(left.corr[4], 0.0);
  const auto right = rig.under({lo, -w});
  EXPECT_NEAR(right.hi[4] - right.lo[4], 2.0 * kSwingDeg, 0.5);
  EXPECT_NEAR(0.5 * (right.hi[4] + right.lo[4]), -kMeanDeg, 0.5);  // the other way round
  EXPECT_LT(right.corr[4], 0.0);
  // Half the turn at the fastest walk: scaled by 1/2 x slowest / fastest speed.
  const auto fast = rig.under({hi, 0.5 * w});
  EXPECT_NEAR(0.5 * (fast.hi[4] + fast.lo[4]), kMeanDeg * 0.5 * lo / hi, 0.1);
  EXPECT_NEAR(fast.hi[4] - fast.lo[4], 2.0 * kSwingDeg * 0.5 * lo / hi, 0.2);
}

// A constant yaw curve steers the legs like wheels: the angle for a turn
// rate w at speed v is the curve x (w / max turn) x (slowest / v).
TEST(SteeredGait, ConstantYawCurveSteersByTurnOverSpeed) {
  ExtendedRig rig("\n  steer: \"8\"",
                  "\n  front: {curve: steer, limb: lf}\n  hind: {curve: steer, limb: lh, sign: -1}",
                  {"front", "hind"}, "  yaw_joints: [front, hind]\n");
  const double lo = rig.st().min_speed_m_s(), w = rig.st().max_turn_rad_s;
  auto a = rig.under({lo, w});
  EXPECT_NEAR(a.lo[4], 8.0, 1e-9);
  EXPECT_NEAR(a.hi[4], 8.0, 1e-9);
  EXPECT_NEAR(a.lo[5], -8.0, 1e-9);
  a = rig.under({2.0 * lo, -0.5 * w});
  EXPECT_NEAR(a.mean[4], -2.0, 1e-9);
  EXPECT_NEAR(a.mean[5], 2.0, 1e-9);
  a = rig.under({2.0 * lo, 0.0});
  EXPECT_EQ(a.hi[4], 0.0);
}

TEST(SteeredGait, LiftCurvesKeepTheirWholeSwing) {
  ExtendedRig rig("\n  lift: \"-20 + 10*sin(2*PI*t)\"", "\n  lf_knee: {curve: lift, limb: lf}",
                  {"lf_knee"}, "  lift_curves: [lift]\n");
  const double lo = rig.st().min_speed_m_s(), hi = rig.st().max_speed_m_s();
  const double w = rig.st().max_turn_rad_s;
  for (const MotionCommand c : {MotionCommand{lo, 0.0}, MotionCommand{hi, 0.0},
                                MotionCommand{lo, w}, MotionCommand{hi, -w}}) {
    const auto s = rig.under(c);
    EXPECT_NEAR(s.hi[4] - s.lo[4], 20.0, 0.05) << c.speed_m_s << " " << c.turn_rad_s;
  }
  // The hip of the same left leg follows the stride length and the turn.
  const auto slow = rig.under({lo, 0.0});
  const auto turning = rig.under({lo, 0.5 * w});
  EXPECT_LT(slow.hi[0] - slow.lo[0], 2.0 * kSwingDeg * 0.9);
  EXPECT_LT(turning.hi[0] - turning.lo[0], slow.hi[0] - slow.lo[0] - 1.0);
  // Standing still stands the lift curves too, at their mean.
  const auto stand = rig.under({0.0, 0.0});
  EXPECT_NEAR(stand.lo[4], -20.0, 1e-6);
  EXPECT_NEAR(stand.hi[4], -20.0, 1e-6);
}

// Time between the first and the last upward crossing of lf_hip's mean over
// `seconds`, divided by the crossings between them: the stride period.
double stride_period(ExtendedRig& rig, MotionCommand command, double seconds) {
  rig.under(command);
  double prev = rad_to_deg(rig.targets[0]) - kMeanDeg;
  double first = -1.0, last = -1.0;
  int crossings = 0;
  for (long k = 0; k < std::lround(seconds / kDt); ++k, rig.t += kDt) {
    rig.source->sample(rig.t, rig.targets);
    const double d = rad_to_deg(rig.targets[0]) - kMeanDeg;
    if (prev < 0.0 && d >= 0.0) {
      if (first < 0.0) first = rig.t;
      last = rig.t;
      ++crossings;
    }
    prev = d;
  }
  return crossings > 1 ? (last - first) / (crossings - 1) : 0.0;
}

TEST(SteeredGait, FixedCadenceKeepsTheStrideFrequencyAndScalesTheSwingBySpeed) {
  ExtendedRig fixed("", "", {}, "  fixed_cadence: true\n");
  ExtendedRig froude("", "", {}, "");
  const double lo = fixed.st().min_speed_m_s(), hi = fixed.st().max_speed_m_s();
  // The gait's own 1 Hz at every speed; the Froude timing is slower at the
  // slowest walk and faster at the fastest.
  EXPECT_NEAR(stride_period(fixed, {lo, 0.0}, 8.0), 1.0, 0.01);
  EXPECT_NEAR(stride_period(fixed, {hi, 0.0}, 8.0), 1.0, 0.01);
  const double h = fixed.st().hip_height_m;
  const double fr_lo = lo / std::sqrt(kStandardGravity * h);
  EXPECT_NEAR(stride_period(froude, {lo, 0.0}, 8.0), 1.0 / froude_stride_frequency(fr_lo, h), 0.01);
  // Swing proportional to speed: stride length v / f at a fixed f.
  const double native = dynamic_cast<SteeredGaitSource&>(*fixed.source).native_speed_m_s();
  const auto s = fixed.under({lo, 0.0});
  EXPECT_NEAR(s.hi[0] - s.lo[0], 2.0 * kSwingDeg * lo / native, 0.1);
}

TEST(SteeredGait, SwingOffsetShiftsTheSwingForASpeed) {
  ExtendedRig rig("", "", {}, "  fixed_cadence: true\n  swing_offset: -0.5\n");
  const double v = rig.st().max_speed_m_s();
  const double native = dynamic_cast<SteeredGaitSource&>(*rig.source).native_speed_m_s();
  const auto s = rig.under({v, 0.0});
  // swing_offset + (1 - swing_offset) v / v_native of the curve's swing.
  EXPECT_NEAR(s.hi[0] - s.lo[0], 2.0 * kSwingDeg * (-0.5 + 1.5 * v / native), 0.1);
}

// Speed 0 with a turn: standing, unless the gait turns on the spot; then
// the legs step in place, the sides swinging against each other about the
// spot swing offset as for -+turn x half the spot track, the yaw joints at
// rest.
TEST(SteeredGait, TurnOnTheSpotStepsInPlaceWithTheSidesAgainstEachOther) {
  const std::string steering = "  fixed_cadence: true\n  swing_offset: -0.5\n  yaw_joints: [yaw]\n";
  const std::string yaw = "\n  yaw: {curve: hip, limb: lf}";
  ExtendedRig stands("", yaw, {"yaw"}, steering);
  const double w = 0.3;
  const auto still = stands.under({0.0, w});
  for (std::size_t j = 0; j < 4; ++j) EXPECT_LT(still.hi[j] - still.lo[j], 1e-9) << j;
  ExtendedRig rig("", yaw, {"yaw"},
                  steering +
                      "  turn_on_the_spot: true\n  spot_track_width_m: 0.4\n"
                      "  spot_swing_offset: -0.2\n");
  const auto s = rig.under({0.0, w});
  const double native = dynamic_cast<SteeredGaitSource&>(*rig.source).native_speed_m_s();
  // Fixed cadence: (1 - swing_offset) x (v / native) for a side walking v.
  const double differential = 1.5 * w * 0.2 / native;
  const double left = -0.2 - differential, right = -0.2 + differential;
  ASSERT_GT(right, 0.0);  // the outer side swings forward, the inner back
  EXPECT_NEAR(s.hi[0] - s.lo[0], 2.0 * kSwingDeg * std::abs(left), 0.1);   // lf
  EXPECT_NEAR(s.hi[2] - s.lo[2], 2.0 * kSwingDeg * std::abs(left), 0.1);   // lh
  EXPECT_NEAR(s.hi[1] - s.lo[1], 2.0 * kSwingDeg * std::abs(right), 0.1);  // rf
  EXPECT_NEAR(s.hi[3] - s.lo[3], 2.0 * kSwingDeg * std::abs(right), 0.1);  // rh
  EXPECT_LT(s.hi[4] - s.lo[4], 1e-9);                                      // the yaw joint rests
  const MotionCommand now = dynamic_cast<SteeredGaitSource&>(*rig.source).current();
  EXPECT_EQ(now.speed_m_s, 0.0);
  EXPECT_NEAR(now.turn_rad_s, w, 1e-12);
  // Back to walking straight: the ordinary swing on both sides.
  const double v = rig.st().max_speed_m_s();
  const auto walk = rig.under({v, 0.0});
  EXPECT_NEAR(walk.hi[0] - walk.lo[0], 2.0 * kSwingDeg * (-0.5 + 1.5 * v / native), 0.1);
  EXPECT_NEAR(walk.hi[1] - walk.lo[1], walk.hi[0] - walk.lo[0], 1e-6);
}

TEST(SteeredGait, SteerAndSampleDoNotAllocate) {
  Rig rig;
  rig.source->sample(0.0, rig.targets);
  test::AllocationCounter counter;
  for (int k = 1; k < 2000; ++k) {
    if (k % 100 == 0) rig.source->steer({0.02 * (k % 700) / 100.0, 0.1 * ((k / 100) % 3 - 1)});
    rig.source->sample(k * kDt, rig.targets);
  }
  EXPECT_EQ(counter.count(), 0);
}

}  // namespace
}  // namespace animrt
