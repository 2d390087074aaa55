// The balance reflex's control law (see balance_reflex.hpp).

#include "animrt/controllers/gait/balance_reflex.hpp"

#include <algorithm>

namespace animrt {

void BalanceReflex::update(const TrunkTilt& tilt, double dt_s) {
  nose_rate_ = started_ ? (tilt.nose_up - tilt_.nose_up) / dt_s : 0.0;
  left_rate_ = started_ ? (tilt.left_up - tilt_.left_up) / dt_s : 0.0;
  started_ = true;
  tilt_ = tilt;
}

double BalanceReflex::stretch(const BalanceLeg& leg, bool on_ground) const {
  if (!on_ground) return 0.0;
  // This leg's end of the trunk is down by -(sine of it being up).
  const double down = -(leg.front * tilt_.nose_up + leg.left * tilt_.left_up);
  const double down_rate = -(leg.front * nose_rate_ + leg.left * left_rate_);
  return std::clamp(gains_.tilt_m * down + gains_.tilt_rate_m_s * down_rate, -kMaxBalanceStretchM,
                    kMaxBalanceStretchM);
}

bool leg_stretch_to_joints(double stretch_m, std::span<const double> down_per_rad,
                           std::span<double> delta_rad) {
  double norm = 0.0;
  for (double g : down_per_rad) norm += g * g;
  if (norm < 1e-12) return false;
  for (std::size_t i = 0; i < down_per_rad.size(); ++i) {
    delta_rad[i] = down_per_rad[i] * stretch_m / norm;
  }
  return true;
}

}  // namespace animrt
