#pragma once
// How a steerable gait walks: the limits of its `steering` section and,
// when the gait has been calibrated on physics (`animrt gait calibrate`),
// the table of commanded against achieved speed and turn rate. The herd
// asks a figure only for what this says it can walk, and moves the figure
// by what it achieves.

#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_steering.hpp"
#include "animrt/controllers/motion_source.hpp"

namespace animrt {

// One calibrated command: what the figure walked when told to.
struct CalibrationPoint {
  MotionCommand commanded;
  MotionCommand achieved;
  bool fell = false;
  // achieved speed and turn within the tolerance of the commanded ones, no
  // fall (calibration_usable)
  bool usable = false;
};

struct GaitCalibration {
  std::string gait_file;    // the gait it was measured for
  std::string model_file;   // the MJCF model it walked on
  double tolerance = 0.15;  // relative speed and turn error accepted as usable
  std::vector<CalibrationPoint> points;
  // Where the gait and model keys are (read from a file), for messages.
  Location gait_where, model_where;
};

bool operator==(const MotionCommand& a, const MotionCommand& b);
// Compares content (usable included).
bool operator==(const CalibrationPoint& a, const CalibrationPoint& b);
bool operator==(const GaitCalibration& a, const GaitCalibration& b);

// The smallest turn-rate error a usable point may have, degrees/s: a
// straight walk (turn command 0) may drift this much, and a slow turn may
// miss by this much, without being judged unusable.
inline constexpr double kCalibrationTurnFloorDps = 1.0;

// The most a turn on the spot may drift along the heading, m/s: 1 cm/s, a
// tenth of a pony's walk (10 cm while it turns round in 10 s).
inline constexpr double kCalibrationSpotDriftMps = 0.01;

// Whether a measured point counts as usable under `tolerance`: no fall, the
// achieved speed within tolerance x commanded of the commanded speed (a turn
// on the spot, speed 0: within kCalibrationSpotDriftMps of standing), and
// the achieved turn rate within max(tolerance x |commanded turn|,
// kCalibrationTurnFloorDps) of the commanded turn rate.
bool calibration_usable(const CalibrationPoint& point, double tolerance);

// walk.yaml -> walk.calibration.yaml (next to the gait).
std::string calibration_path_for(const std::string& gait_path);
// Reads a calibration file (format: docs/gait.md). Throws InputError naming
// the file, line, column and key (also for a `usable` flag that contradicts
// the tolerance).
GaitCalibration load_gait_calibration(const std::string& path);
GaitCalibration parse_gait_calibration(const std::string& text, const std::string& file_name);
// The table's references, resolved against `calibration_path`'s folder:
// `gait` must be the gait at `gait_path` (a table measured for another gait
// would steer this one wrongly) and `model` a readable file. Throws
// InputError at the key.
void check_calibration_references(const GaitCalibration& calibration,
                                  const std::string& calibration_path,
                                  const std::string& gait_path);
std::string format_gait_calibration(const GaitCalibration& calibration);
// Throws std::runtime_error when the file cannot be written.
void write_gait_calibration(const std::string& path, const GaitCalibration& calibration);

class WalkResponse {
 public:
  // Without a calibration the figure walks exactly what it is told, within
  // the steering limits. With one, only commands the table marks usable are
  // given, and achieved() interpolates the table: the speeds are the longest
  // run of measured speeds whose straight walk is usable, and at each speed
  // the turn rates those usable points reach from the straight walk without
  // crossing an unusable one.
  explicit WalkResponse(const GaitSteering& steering, const GaitCalibration* calibration = nullptr);

  // Walking speeds the figure can be asked for: 0 (standing) or
  // [min_speed(), max_speed()].
  double min_speed() const;
  double max_speed() const;
  // Fastest usable turn rate at `speed` (rad/s, either way).
  double max_turn(double speed) const;
  double max_acceleration() const;
  // Fastest turn on the spot either way (rad/s; speed 0): the steering's
  // max turn when `turn_on_the_spot` is set and there is no calibration,
  // with one the fastest its usable speed-0 rows reach from either side
  // without crossing an unusable one; 0 when the figure cannot.
  double spot_turn() const;

  // What the figure walks when given `commanded` (clamped to the usable
  // range first; a speed of 0 with a turn turns on the spot within
  // spot_turn(), interpolating the speed-0 rows when calibrated).
  MotionCommand achieved(const MotionCommand& commanded) const;
  // The usable command whose achieved motion comes closest to `wanted`.
  MotionCommand command_for(const MotionCommand& wanted) const;

 private:
  // Usable points of one commanded speed, sorted by commanded turn.
  struct Level {
    double speed = 0.0;
    std::vector<CalibrationPoint> points;
  };
  double level_max_turn(const Level& level) const;
  MotionCommand level_achieved(const Level& level, double turn) const;
  MotionCommand clamp(const MotionCommand& command) const;
  MotionCommand spot_achieved(double turn) const;

  GaitSteering steering_;
  bool calibrated_ = false;
  std::vector<Level> levels_;  // by commanded speed
  Level spot_;                 // usable speed-0 rows reached from standing, by turn
  struct Node {
    MotionCommand commanded, achieved;
  };
  std::vector<Node> grid_;  // calibrated only: where command_for starts
};

// The walk response of a steerable gait: its steering section, and its
// calibration (calibration_path_for(gait_path)) when that file exists.
// Throws InputError when the gait has no steering section, or for errors in
// either file.
WalkResponse load_walk_response(const std::string& gait_path);

}  // namespace animrt
