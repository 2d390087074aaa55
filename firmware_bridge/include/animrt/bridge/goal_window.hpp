#pragma once
// The goals a servo bus may send one joint. Normally the joint's limits
// (inside the servo's range). A joint found resting outside them at bring-up
// (a hanging jaw) gets a window widened to where it is, so torque on holds it
// there rather than snapping it to a limit; every goal sent then narrows the
// window again, so a goal never goes back out past one already sent and,
// once inside, the joint stays inside.

#include <cstdint>
#include <limits>
#include <string>

#include "animrt/bridge/bus_config.hpp"

namespace animrt {

struct GoalWindow {
  double limit_lo = -std::numeric_limits<double>::infinity();  // the joint's limits
  double limit_hi = std::numeric_limits<double>::infinity();
  double lo = limit_lo;  // what goals may be now
  double hi = limit_hi;

  // The joint's limits from its binding, inside the servo's range
  // [range_lo_ticks, range_hi_ticks]; the window is set to them.
  static GoalWindow for_joint(const ActuatorBinding& b, std::int32_t range_lo_ticks,
                              std::int32_t range_hi_ticks);

  // Back to the joint's limits, then widened to include `present_ticks` if
  // the joint rests outside them by a tick or more. Returns the warning's
  // text for this joint ("-3.0 deg, outside its limits 0.0..30.0 deg"),
  // empty when it is inside.
  std::string start_at(const ActuatorBinding& b, std::int32_t present_ticks);

  double clamp(double rad) const;
  // After `goal` (finite) was sent: the window closes in behind it.
  void narrow(double goal);
};

// The warning a bus prints after configure() for the joints resting outside
// (`joints`: "id 4 (jaw) is at ...; ..."): what it did and what to check.
// `limits_name` is the servo's name for its limit registers.
std::string outside_limits_warning(const std::string& joints, const char* limits_name);

}  // namespace animrt
