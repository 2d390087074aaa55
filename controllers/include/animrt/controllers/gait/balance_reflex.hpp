#pragma once
// The gait's balance reflex (GaitBalance, gait_file.hpp) as a control law on
// plain inputs, so that whoever plays the gait (the fitness walk on MuJoCo
// today, the runtime once it reads an IMU) measures the inputs and applies
// the outputs, and the law itself is one piece of code.
//
// Inputs per step: the trunk's tilt (the world-vertical components of its
// forward and left axes, i.e. the sines of the nose and the left side being
// up), the step's length, and for each leg where its foot sits on the trunk
// and whether it is on the ground. Output per leg: how far to lengthen it
// along the trunk's vertical (m), and, given the leg's Jacobian along that
// vertical, the joint changes that do it.

#include <span>

#include "animrt/controllers/gait/gait_file.hpp"

namespace animrt {

// Where a leg's foot is on the trunk: +1 in front of / left of the trunk's
// centre, -1 behind / right of it.
struct BalanceLeg {
  double front = 1.0;
  double left = 1.0;
};

// The trunk's attitude as the reflex reads it (dimensionless sines).
struct TrunkTilt {
  double nose_up = 0.0;  // world z of the trunk's forward axis
  double left_up = 0.0;  // world z of the trunk's left axis
};

class BalanceReflex {
 public:
  explicit BalanceReflex(const GaitBalance& gains) : gains_(gains) {}

  // One control step `dt_s` long with the trunk at `tilt`. The tilt rates are
  // the differences from the previous step (zero on the first).
  void update(const TrunkTilt& tilt, double dt_s);

  // How far (m) to lengthen `leg` along the trunk's vertical this step:
  //   tilt_m * d + tilt_rate_m_s * d'
  // with d how far its side (roll) and end (pitch) of the trunk is down and
  // d' its rate, clamped to +-kMaxBalanceStretchM. A leg in the air gets 0:
  // only a leg on the ground holds the trunk up, and a swing leg stretched
  // would stub its foot (measured: the seed walk then falls 2 to 8 of 10).
  double stretch(const BalanceLeg& leg, bool on_ground) const;

  // Back to before the first step.
  void reset() { started_ = false; }

 private:
  GaitBalance gains_;
  TrunkTilt tilt_;
  double nose_rate_ = 0.0, left_rate_ = 0.0;  // 1/s
  bool started_ = false;
};

// A leg's stretch as joint changes, least-norm: `down_per_rad[i]` is how far
// (m) the foot moves down the trunk's vertical per radian of the leg's joint
// i (its Jacobian along that axis), so the leg needs no model of how it is
// built. Writes one change (rad) per joint into `delta_rad` (same size) and
// returns true; returns false and writes nothing when no joint moves the
// foot along the vertical.
bool leg_stretch_to_joints(double stretch_m, std::span<const double> down_per_rad,
                           std::span<double> delta_rad);

}  // namespace animrt
