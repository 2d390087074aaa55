#pragma once
// How a steerable gait walks: the limits of its `steering` section and,
// when the gait has been calibrated on physics (`animrt gait calibrate`),
// the table of commanded against achieved speed and turn rate. The herd
// asks a figure only for what this says it can walk, and moves the figure
// by what it achieves.

#include <string>
#include <vector>

#include "animrt/controllers/motion_source.hpp"

namespace animrt {

// The `steering` section of a gait file (documented in docs/gait.md).
struct GaitSteering {
  double min_froude = 0.0;             // slowest walking Froude number (> 0)
  double max_froude = 0.0;             // fastest
  double max_turn_rad_s = 0.0;         // fastest turn rate, either way
  double max_acceleration_m_s2 = 0.0;  // forward speed changes at most this fast
  double hip_height_m = 0.0;           // h of Fr = v / sqrt(g h)

  double min_speed_m_s() const;
  double max_speed_m_s() const;
};

// One calibrated command: what the figure walked when told to.
struct CalibrationPoint {
  MotionCommand commanded;
  MotionCommand achieved;
  bool fell = false;
  // achieved speed within the tolerance of the commanded one, no fall
  bool usable = false;
};

struct GaitCalibration {
  std::string gait_file;   // the gait it was measured for
  std::string model_file;  // the MJCF model it walked on
  double tolerance = 0.15; // relative speed error accepted as usable
  std::vector<CalibrationPoint> points;
};

// walk.yaml -> walk.calibration.yaml (next to the gait).
std::string calibration_path_for(const std::string& gait_path);
// Throws InputError naming the file, line and key.
GaitCalibration load_gait_calibration(const std::string& path);
void write_gait_calibration(const std::string& path, const GaitCalibration& calibration);

class WalkResponse {
 public:
  // Without a calibration the figure walks exactly what it is told, within
  // the steering limits. With one, only commands the table marks usable are
  // given, and achieved() interpolates the table.
  explicit WalkResponse(const GaitSteering& steering, const GaitCalibration* calibration = nullptr);

  // Walking speeds the figure can be asked for: 0 (standing) or
  // [min_speed(), max_speed()].
  double min_speed() const;
  double max_speed() const;
  // Fastest usable turn rate at `speed` (rad/s, either way).
  double max_turn(double speed) const;
  double max_acceleration() const;

  // What the figure walks when given `commanded` (clamped to the usable
  // range first).
  MotionCommand achieved(const MotionCommand& commanded) const;
  // The usable command whose achieved motion comes closest to `wanted`.
  MotionCommand command_for(const MotionCommand& wanted) const;

 private:
  GaitSteering steering_;
  std::vector<CalibrationPoint> usable_;  // sorted by commanded speed, then turn
};

}  // namespace animrt
