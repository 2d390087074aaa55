#pragma once
// The gait file (configs/gaits/*.yaml, format documented in
// configs/gaits/walk.yaml): named curves in the expression language, phase
// delays per limb, and the mapping of robot joints onto curves and limbs.
//
// load_gait_file() validates everything that does not depend on a robot;
// binding to a robot's joints is make_gait_source() (gait_source.hpp).
// write_gait_file() writes a file that loads back equal, so an evolved gait
// can be saved and replayed.

#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_steering.hpp"
#include "animrt/core/error.hpp"

namespace animrt {

// Locations (`where`) say where an item was read from, for error messages;
// they are not part of an item's value and are ignored by ==.

struct GaitCurve {
  std::string name;
  // Joint angle (degrees) as a function of t in stride cycles.
  std::string expression;
  Location where;  // of the expression's first character
};

struct GaitLimb {
  std::string name;
  double phase = 0.0;  // delay in stride cycles, 0..1
  Location where;
};

struct GaitJoint {
  std::string name;   // robot joint name
  std::string curve;  // a GaitCurve name
  std::string limb;   // a GaitLimb name
  int sign = 1;       // +1 or -1
  double scale = 1.0;
  double offset_deg = 0.0;
  Location where;  // of the joint's key
};

struct FroudeTiming {
  double number = 0.0;        // Fr = v / sqrt(g h)
  double hip_height_m = 0.0;  // h
};

// A leg stretches by at most this much for balance: more lifts a foot off
// the ground or folds the leg.
constexpr double kMaxBalanceStretchM = 0.1;

// A balance reflex through leg length, for a figure whose legs cannot step
// sideways: each leg on the ground is lengthened along the trunk's vertical by
//   tilt_m * d + tilt_rate_m_s * d'
// where d is how far its side or end of the trunk is down (the sine of the
// roll for left and right, of the pitch for front and back) and d' its rate,
// so the low side is pushed back up and a swaying trunk is damped. The law
// is BalanceReflex (balance_reflex.hpp). It needs the trunk's attitude, which
// the fitness walk and `gait measure` read from the physics and the runtime
// from the robot's IMU (BalancedGaitSource), and the legs (LegModel).
struct GaitBalance {
  double tilt_m = 0.0;         // m of leg length per unit of tilt sine
  double tilt_rate_m_s = 0.0;  // m of leg length per unit of tilt sine per second
  Location where;              // of the balance key
};

struct GaitFile {
  std::string name;
  // Exactly one of these is set.
  std::optional<double> stride_frequency_hz;
  std::optional<FroudeTiming> froude;
  std::vector<GaitCurve> curves;  // in file order
  std::vector<GaitLimb> limbs;
  std::vector<GaitJoint> joints;
  // Present when the gait can be steered (speed and turn commands); without
  // it the gait plays at its own timing and ignores commands.
  std::optional<GaitSteering> steering;
  std::optional<GaitBalance> balance;
  // false: a periodic motion that carries no weight (an animatronic's
  // neck sway), not a walk: a stop ramps it home at once instead of
  // winding it down to a stand first.
  bool walks = true;
  Location walks_where;  // of the walks key
  std::string file;      // where it was loaded from ("" when built in memory)

  // Stride cycles per second, from whichever timing is set (0 if neither).
  double stride_frequency() const;

  const GaitCurve* find_curve(const std::string& curve_name) const;
  const GaitLimb* find_limb(const std::string& limb_name) const;
};

bool operator==(const GaitCurve& a, const GaitCurve& b);
bool operator==(const GaitLimb& a, const GaitLimb& b);
bool operator==(const GaitJoint& a, const GaitJoint& b);
bool operator==(const FroudeTiming& a, const FroudeTiming& b);
bool operator==(const GaitBalance& a, const GaitBalance& b);
// Compares content; `file` and locations are ignored.
bool operator==(const GaitFile& a, const GaitFile& b);

// Reads and validates a gait file. Throws InputError (file:line:column: key:
// message) for a missing file, YAML errors, unknown keys, wrong types, bad
// timing, expression errors (at their column in the file), undefined curves
// or limbs, curves that are not finite over a stride, and a gait without
// joints.
GaitFile load_gait_file(const std::string& path);

// The same from text, reported as `file_name` (for tests and embedded text).
GaitFile parse_gait_file(const std::string& text, const std::string& file_name);

// Checks a gait built in memory (e.g. by the evolver) as load_gait_file
// checks a file, reporting at the items' locations. load_gait_file and
// parse_gait_file have already done this.
void validate_gait(const GaitFile& gait);

// Text of a gait file that parse_gait_file reads back equal (numbers are
// written in their shortest exact form).
std::string format_gait_file(const GaitFile& gait);

// Writes format_gait_file(gait) to `path`. Throws std::runtime_error when the
// file cannot be written.
void write_gait_file(const GaitFile& gait, const std::string& path);

}  // namespace animrt
