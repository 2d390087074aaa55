// The gait subcommand: calibrate a steerable gait on MuJoCo physics.

#include "gait_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>

#include "animrt/controllers/gait/froude.hpp"
#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/gait/walk_response.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/sim/mujoco/mujoco_walk.hpp"
#include "option_checks.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct CalibrateArgs {
  std::string robot;
  std::string physics;
  std::string gait;  // overrides the robot's motion.file
  std::string out;
  int speeds = 5;
  int turns = 2;
  std::uint64_t seed = 0;
};

constexpr double kSettleS = 0.5;
constexpr double kWarmupStrides = 3.0;
constexpr double kMeasureStrides = 4.0;

// Normalised on both sides, so the table names ../gaits/walk.yaml, not a
// path through the robot file's folder.
std::string relative_to(const std::string& path, const std::string& from_file) {
  std::error_code ec;
  const auto base = std::filesystem::absolute(from_file, ec).lexically_normal().parent_path();
  const auto rel = std::filesystem::absolute(path, ec).lexically_normal().lexically_relative(base);
  return rel.empty() ? path : rel.string();
}

// A table without a usable turn steers nothing: the runtime walks the gait
// straight. Said, and why, rather than left to be found on the figure.
void explain_turns(const GaitCalibration& cal, const GaitSteering& st, int turns) {
  const bool turning = std::any_of(cal.points.begin(), cal.points.end(), [](const auto& p) {
    return p.usable && p.commanded.turn_rad_s != 0.0;
  });
  if (turning) return;
  if (turns == 0) {
    std::printf("--turns 0: no turn was tried; the table walks the gait straight only\n");
    return;
  }
  std::printf("no turn is usable: the table walks the gait straight only");
  if (turns == 1) {
    std::printf(
        " (--turns 1 tries only the fastest turns, +-%.1f deg/s; --turns 2 or more "
        "tries gentler ones too)",
        rad_to_deg(st.max_turn_rad_s));
  }
  std::printf("\n");
}

// One point of the table: the gait walked from standing at `command` on the
// model, measured after `ramp_s` plus the warm-up strides. Prints its row.
CalibrationPoint measure_point(const sim::MujocoModel& model, const GaitFile& gait,
                               const std::vector<JointSpec>& specs, const MotionCommand& command,
                               double stride_s, double ramp_s, std::uint64_t seed,
                               double tolerance) {
  sim::WalkTrial trial;
  trial.settle_s = kSettleS;
  trial.warmup_s = ramp_s + kWarmupStrides * stride_s;
  trial.measure_s = kMeasureStrides * stride_s;
  trial.seed = seed;
  auto source = make_gait_source(gait, specs);
  const sim::WalkTrace trace = sim::walk_command(model, *source, command, trial);
  CalibrationPoint p;
  p.commanded = command;
  p.achieved = trace.achieved;
  p.fell = trace.fell;
  p.usable = calibration_usable(p, tolerance);
  const double v = command.speed_m_s, w = command.turn_rad_s;
  std::printf(
      "%10.4f %9.2f | %10.4f %9.2f %7.1f %9.2f  %s\n", v, rad_to_deg(w), p.achieved.speed_m_s,
      rad_to_deg(p.achieved.turn_rad_s), v > 0.0 ? 100.0 * (p.achieved.speed_m_s - v) / v : 0.0,
      rad_to_deg(p.achieved.turn_rad_s - w), p.fell ? "FELL" : (p.usable ? "usable" : "off"));
  return p;
}

int run_calibrate(const CalibrateArgs& a) {
  std::string gait_path = a.gait;
  if (gait_path.empty()) {
    const RobotConfig config = load_robot_config(a.robot);
    if (config.motion.type != "gait") {
      throw InputError(config.motion.where, "motion.type",
                       "gait calibrate needs a robot whose motion.type is gait, found \"" +
                           config.motion.type + "\"");
    }
    gait_path = config.motion.file;
  }
  const GaitFile gait = load_gait_file(gait_path);
  if (!gait.steering) {
    throw InputError(Location{gait_path, 0, 0}, "steering",
                     "the gait has no steering section; add one (docs/gait.md) to calibrate it");
  }
  const GaitSteering& st = *gait.steering;
  const sim::MujocoModel model = sim::load_mujoco_model(a.physics);
  const auto specs = sim::model_joint_specs(model);
  (void)make_gait_source(gait, specs);  // its joints must be the model's (errors name the gait)

  GaitCalibration cal;
  const std::string out = a.out.empty() ? calibration_path_for(gait_path) : a.out;
  // Checked before the walks (--out itself when the command line was read;
  // the default beside the gait only now, once the gait is known).
  if (const std::string problem = output_file_problem(out); !problem.empty()) {
    throw std::invalid_argument("the calibration file " + out + ": " + problem +
                                " (give another with --out)");
  }
  cal.gait_file = relative_to(gait_path, out);
  cal.model_file = relative_to(a.physics, out);
  std::printf("calibrating %s on %s: %d speeds x %d turn rates\n", gait_path.c_str(),
              a.physics.c_str(), a.speeds, 1 + 2 * a.turns);
  std::printf("%10s %9s | %10s %9s %7s %9s  %s\n", "cmd m/s", "cmd deg/s", "got m/s", "got deg/s",
              "err %", "err deg/s", "");
  for (int i = 0; i < a.speeds; ++i) {
    const double u = a.speeds == 1 ? 0.5 : static_cast<double>(i) / (a.speeds - 1);
    const double fr = st.min_froude + u * (st.max_froude - st.min_froude);
    const double v = froude_velocity(fr, st.hip_height_m);
    const double stride_s = 1.0 / (st.fixed_cadence ? gait.stride_frequency()
                                                    : froude_stride_frequency(fr, st.hip_height_m));
    const double ramp_s = v / st.max_acceleration_m_s2 + stride_s;
    // A gait that turns on the spot gets the speed-0 rows too, once, at
    // the slowest walk's cadence.
    const bool spot_rows = i == 0 && st.turn_on_the_spot;
    for (int k = -a.turns; k <= a.turns; ++k) {
      const double sign = k < 0 ? -1.0 : 1.0;
      const double w = a.turns == 0 ? 0.0 : sign * st.max_turn_rad_s * std::abs(k) / a.turns;
      if (spot_rows && k != 0)
        cal.points.push_back(
            measure_point(model, gait, specs, {0.0, w}, stride_s, stride_s, a.seed, cal.tolerance));
      cal.points.push_back(
          measure_point(model, gait, specs, {v, w}, stride_s, ramp_s, a.seed, cal.tolerance));
    }
  }
  // Standing first, then by speed and turn, so the table reads in order.
  std::stable_sort(cal.points.begin(), cal.points.end(), [](const auto& x, const auto& y) {
    return x.commanded.speed_m_s < y.commanded.speed_m_s ||
           (x.commanded.speed_m_s == y.commanded.speed_m_s &&
            x.commanded.turn_rad_s < y.commanded.turn_rad_s);
  });
  write_gait_calibration(out, cal);
  int usable = 0;
  for (const auto& p : cal.points) usable += p.usable ? 1 : 0;
  std::printf(
      "%d of %zu points usable (speed within %.0f %% of the commanded one, turn within %.0f %% or "
      "%g deg/s, no fall)\nwrote %s\n",
      usable, cal.points.size(), 100.0 * cal.tolerance, 100.0 * cal.tolerance,
      kCalibrationTurnFloorDps, out.c_str());
  explain_turns(cal, st, a.turns);
  return 0;
}

}  // namespace

void add_gait_command(CLI::App& app) {
  auto* gait = app.add_subcommand("gait", "Steerable gaits");
  gait->require_subcommand(1);
  auto args = std::make_shared<CalibrateArgs>();
  auto* cmd = gait->add_subcommand(
      "calibrate", "Walk a robot's steerable gait on MuJoCo over its speed and turn range");
  cmd->add_option("ROBOT", args->robot, "robot file (motion.type gait)")->required();
  cmd->add_option("--physics", args->physics, "MuJoCo MJCF model to walk on")->required();
  cmd->add_option("--gait", args->gait, "gait file to calibrate instead of the robot's");
  cmd->add_option("--out", args->out, "calibration file (default: next to the gait)")
      ->check(kOutputFile);
  cmd->add_option("--speeds", args->speeds, "speeds from min to max Froude")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--turns", args->turns, "turn rates each way (fractions of the fastest)")
      ->check(CLI::Range(0, 20));
  cmd->add_option("--seed", args->seed, "perturb the start pose (0: exact standing pose)")
      ->check(kSeed);
  set_subcommand_body(cmd, [args] { return run_calibrate(*args); });
  add_gait_measure_command(*gait);
}

}  // namespace animrt::cli
