#pragma once
// A gait with a `steering` section: a MotionSource that walks at the
// commanded speed and turn rate (docs/gait.md, "Steering").
//
// Speed v sets Fr = v / sqrt(g h); the stride frequency and stride length
// follow the Froude relations (froude.hpp). Each joint swings about its
// curve's stride mean, with the swing scaled by lambda(Fr) / lambda(Fr_native)
// (foot-lift curves keep their whole swing); a turn scales the inner side's
// swing by (v - w track / 2) / v and the outer side's by (v + w track / 2) / v,
// and turns the yaw joints by their curve scaled by (w / max turn) x
// (slowest speed / v). Speed ramps at
// the steering acceleration, turn rate and walk/stand blend over one stride
// at the slowest speed, and the phase is integrated, so no command makes a
// joint jump. A command below the slowest speed stands: the swing blends
// to 0 (the standing pose is the curve means) and the phase stops; with
// `turn_on_the_spot`, one with a turn steps in place at the slowest
// walk's cadence instead, each side swinging as for -+turn x half the spot
// track about the spot swing offset (the swing that walks nowhere), the
// yaw joints at rest, blended in and out over a stride.

#include <memory>
#include <vector>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/controllers/gait/gait_steering.hpp"
#include "animrt/controllers/motion_source.hpp"

namespace animrt {

class SteeredGaitSource final : public MotionSource {
 public:
  enum Side : int { kNoSide = 0, kLeft = 1, kRight = 2, kYaw = 3 };
  struct Drive {
    int joint = 0;
    int curve = 0;
    double phase = 0.0;  // stride cycles
    double gain = 1.0;   // sign * scale
    double offset_deg = 0.0;
    Side side = kNoSide;
    bool lift = false;  // a foot-lift curve: whole swing at every speed and turn
  };

  // `native_frequency_hz` is the gait's own timing; before any command the
  // source walks at its speed (clamped to the steering range).
  SteeredGaitSource(const GaitSteering& steering, double native_frequency_hz,
                    std::vector<Expression> curves, std::vector<Drive> drives);

  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override;
  void steer(const MotionCommand& command) override;
  // A stop: the walk is told to stand (as a command under the slowest
  // speed), and the swing blends out over the walk/stand blend time, or
  // faster to stand within the time granted.
  double wind_down(double t, double granted_s) override;

  // The command in force after clamping (speed 0 = stand).
  MotionCommand target() const { return {target_speed_, target_turn_}; }
  double native_speed_m_s() const { return native_speed_; }
  // Speed and turn rate the playback is at now (speed 0 when standing; the
  // walk/stand blend scales it).
  MotionCommand current() const;

 private:
  void advance(double t) const;
  // Stride frequency at a walking speed, and stride length over the native one.
  double frequency_at(double speed) const;
  double length_ratio_at(double speed) const;
  void reset(double t) const;

  GaitSteering steering_;
  std::vector<Expression> curves_;
  std::vector<double> means_;  // per curve, over one stride
  std::vector<Drive> drives_;
  std::vector<int> driven_;
  double native_speed_ = 0.0;
  double native_length_ = 0.0;  // stride length at the native Froude number
  double native_frequency_hz_ = 1.0;
  double blend_time_s_ = 1.0;  // walk/stand blend and full-turn ramp time
  double stand_time_s_ = 1.0;  // the same towards a stand (shorter in a granted wind-down)
  double min_speed_ = 0.0, max_speed_ = 0.0;

  double target_speed_ = 0.0;  // 0 or within [min_speed_, max_speed_]
  double target_turn_ = 0.0;   // within +-max turn
  bool target_spot_ = false;   // speed 0 with a turn: turn on the spot

  // Integrated playback state. sample() is const in the interface but is
  // called once per cycle with non-decreasing t, so it advances this state
  // by the time since the previous sample; t <= 0 or a t earlier than the
  // previous one starts over, at the phase of walking the command in force
  // since t = 0. Only the cycle thread touches it.
  mutable bool started_ = false;
  mutable double last_t_ = 0.0;
  mutable double phase_ = 0.0;  // stride cycles
  mutable double speed_ = 0.0;  // walking speed, within [min_speed_, max_speed_]
  mutable double turn_ = 0.0;   // rad/s
  mutable double blend_ = 0.0;  // 0 standing .. 1 walking (linear; smoothed when applied)
  mutable double spot_ = 0.0;   // 0 walking .. 1 turning on the spot (linear, smoothed)
};

}  // namespace animrt
