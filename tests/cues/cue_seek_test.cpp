// A cue asked for at a time into it (a timecode that jumped into its
// middle) plays from there: the step that time falls in, at the time into
// that step, blended in by the crossfade; the chase says how far into the
// cue the timecode is.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/runtime/ltc_chase.hpp"

namespace animrt {
namespace {

// Joint 0 at base + 0.1 t.
class Ramp final : public MotionSource {
 public:
  explicit Ramp(double base) : base_(base) {}
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override { targets[0] = base_ + 0.1 * t; }

 private:
  double base_;
  std::vector<int> driven_{0};
};

Cue ramp_cue(const std::string& name, std::vector<std::pair<double, double>> steps) {
  Cue cue;
  cue.name = name;
  cue.crossfade_s = 0.5;
  for (const auto& [base, duration] : steps) {
    cue.steps.push_back(CueStep{std::make_unique<Ramp>(base), duration});
  }
  return cue;
}

TEST(CueSeek, ACueAskedForAtATimeIntoItPlaysFromThereThroughTheCrossfade) {
  std::vector<Cue> cues;
  cues.push_back(ramp_cue("idle", {{0.0, kForever}}));
  // Two steps: 2 s of a ramp from 0.5, then a ramp from 1.0 until asked otherwise.
  cues.push_back(ramp_cue("show", {{0.5, 2.0}, {1.0, kForever}}));
  const std::vector<JointSpec> joints{{"pan", {-10.0, 10.0, 100.0, 1000.0}, 0.0}};
  CueRequests requests;
  CuePlayer player(std::move(cues), 0, joints, requests);
  std::vector<double> x(1, 0.0);
  double t = 0.0, last = 0.0, largest_step = 0.0;
  for (; t < 1.0; t += 0.01) player.sample(t, x);
  requests.cue(1, 3.5);  // 1.5 s into its second step
  const double asked_at = t;
  for (; t < asked_at + 2.0; t += 0.01) {
    last = x[0];
    player.sample(t, x);
    largest_step = std::max(largest_step, std::abs(x[0] - last));
  }
  EXPECT_EQ(player.current_cue(), 1);
  EXPECT_EQ(player.starts(1), 1u);
  const double elapsed = t - 0.01 - asked_at;
  EXPECT_NEAR(x[0], 1.0 + 0.1 * (1.5 + elapsed), 1e-6);
  // Blended in: the ramp's gap of 1.1 over the 0.5 s crossfade (peak slope
  // 1.875 gap / T: 0.041 per 10 ms), never a jump.
  EXPECT_LT(largest_step, 0.05);

  // Past a looping cue's pass: the same place in its next pass.
  std::vector<Cue> looping;
  looping.push_back(ramp_cue("idle", {{0.0, kForever}}));
  looping.push_back(ramp_cue("loop", {{0.5, 3.0}, {1.0, 1.0}}));
  looping.back().loop = true;
  CueRequests again;
  CuePlayer loop_player(std::move(looping), 0, joints, again);
  loop_player.sample(0.0, x);
  again.cue(1, 9.25);  // 2 passes of 4 s, then 1.25 s into the first step
  for (t = 0.01; t < 1.0; t += 0.01) loop_player.sample(t, x);
  EXPECT_NEAR(x[0], 0.5 + 0.1 * (1.25 + (t - 0.01 - 0.01)), 1e-6);
}

TEST(CueSeek, TheChaseSaysHowFarIntoTheCueTheTimecodeIs) {
  LtcChase chase(25, 0.5, {{0.4, 1}, {599.0, 2}});
  constexpr double kFrame = 1.0 / 25;
  for (int i = 0; i < 25; ++i) {
    chase.frame(i * kFrame, (i + 1) * kFrame);
    if (chase.advance((i + 1) * kFrame) == 1) {
      // As it crossed the start: the little past it that the input's block was.
      EXPECT_NEAR(chase.cue_offset(), (i + 1) * kFrame - 0.4, 1e-9);
    }
  }
  // Cued to 00:10:00:00: cue 2, which began at 00:09:59:00, 1.04 s in (the
  // running time at the end of the first frame after the jump).
  chase.frame(600.0, 1.0 + kFrame);
  EXPECT_EQ(chase.advance(1.0 + kFrame), 2);
  EXPECT_NEAR(chase.cue_offset(), 1.04, 1e-9);
}

}  // namespace
}  // namespace animrt
