#pragma once
// The `steering` section of a gait file (docs/gait.md): the range of
// commands a steerable gait accepts and what it needs to turn them into
// stride frequency, stride length and a turn.

#include <string>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt {

struct GaitSteering {
  double min_froude = 0.0;             // slowest walking Froude number (> 0)
  double max_froude = 0.0;             // fastest
  double max_turn_rad_s = 0.0;         // fastest turn rate, either way (degrees/s in the file)
  double max_acceleration_m_s2 = 0.0;  // forward speed changes at most this fast
  double hip_height_m = 0.0;           // h of Fr = v / sqrt(g h)
  double track_width_m = 0.0;          // between the left and the right feet
  std::vector<std::string> left;       // limb names on the left side
  std::vector<std::string> right;      // and on the right
  // Hip yaw (or abduction) joints, robot joints the gait maps: their curve is
  // the motion at the fastest turn to the left at the slowest walk, scaled by
  // (turn / max turn) x (slowest speed / speed), so they rest at their offset
  // when walking straight.
  std::vector<std::string> yaw_joints;
  // Curves that lift the feet (names from `curves`): they keep their whole
  // swing at every walking speed and on both sides; only the other curves'
  // swing follows the stride length and the turn. Empty: every curve follows.
  std::vector<std::string> lift_curves;
  // Fraction of the native swing at which the figure would no longer
  // advance (its feet slip that much each stride): the swing for stride
  // length lambda is swing_offset + (1 - swing_offset) lambda / lambda_native.
  // 0 (the default): the swing is proportional to the stride length.
  double swing_offset = 0.0;
  // Walk at the gait's own stride frequency at every speed (the stride
  // length alone follows the speed, lambda = v / f) instead of the Froude
  // f(Fr): for a figure whose walk only works at one cadence.
  bool fixed_cadence = false;
  // A command of speed 0 and a turn steps in place while the body yaws: the
  // two sides swing against each other as they would walking +-turn x half
  // spot_track_width_m, about spot_swing_offset (the swing that walks
  // nowhere), the yaw joints at rest, at the slowest walk's cadence. false:
  // a speed under the slowest walk stands, whatever the turn.
  bool turn_on_the_spot = false;
  // Feet that slip turn the body less than the track says: the track the
  // sides' swing is computed for on the spot (in a file it defaults to
  // track_width_m; 0 here means track_width_m).
  double spot_track_width_m = 0.0;
  // The swing fraction at which stepping in place stays in place (in a
  // file it defaults to swing_offset).
  double spot_swing_offset = 0.0;
  Location where;  // of the `steering` key; ignored by ==

  double min_speed_m_s() const;
  double max_speed_m_s() const;
};

bool operator==(const GaitSteering& a, const GaitSteering& b);

}  // namespace animrt
