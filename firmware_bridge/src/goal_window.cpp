// The goals a servo bus may send one joint (see goal_window.hpp).

#include "animrt/bridge/goal_window.hpp"

#include <algorithm>
#include <cstdio>
#include <numbers>

namespace animrt {

GoalWindow GoalWindow::for_joint(const ActuatorBinding& b, std::int32_t range_lo_ticks,
                                 std::int32_t range_hi_ticks) {
  GoalWindow w;
  const double a = b.to_rad(range_lo_ticks);
  const double c = b.to_rad(range_hi_ticks);
  w.limit_lo = std::min(a, c);
  w.limit_hi = std::max(a, c);
  if (b.has_limits()) {  // defence in depth: never a goal outside the joint
    w.limit_lo = std::max(w.limit_lo, b.min_position);
    w.limit_hi = std::min(w.limit_hi, b.max_position);
  }
  w.lo = w.limit_lo;
  w.hi = w.limit_hi;
  return w;
}

std::string GoalWindow::start_at(const ActuatorBinding& b, std::int32_t present_ticks) {
  lo = limit_lo;
  hi = limit_hi;
  const std::int32_t a = b.to_ticks(limit_lo);
  const std::int32_t c = b.to_ticks(limit_hi);
  if (present_ticks >= std::min(a, c) && present_ticks <= std::max(a, c)) return {};
  const double at = b.to_rad(present_ticks);
  lo = std::min(lo, at);
  hi = std::max(hi, at);
  constexpr double kDeg = 180.0 / std::numbers::pi;
  char text[160];
  std::snprintf(text, sizeof text, "%.1f deg, outside its limits %.1f..%.1f deg", at * kDeg,
                limit_lo * kDeg, limit_hi * kDeg);
  return text;
}

double GoalWindow::clamp(double rad) const { return std::clamp(rad, lo, hi); }

void GoalWindow::narrow(double goal) {
  const double sent = clamp(goal);
  lo = std::max(lo, std::min(sent, limit_lo));
  hi = std::min(hi, std::max(sent, limit_hi));
}

std::string outside_limits_warning(const std::string& joints, const char* limits_name) {
  return joints + ": its servo's " + limits_name +
         " now include where it is, so torque on holds it there, and the start ramp brings it "
         "inside (check the joint's zero_ticks and limits if this is not expected)";
}

}  // namespace animrt
