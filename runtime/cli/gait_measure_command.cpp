// `animrt gait measure GAIT --physics MODEL.xml`: walks a gait file on a
// MuJoCo model the way the evolver does, from several perturbed starts, and
// prints what it achieved beside the Froude predictions (docs/evolve.md).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/evolve/fitness.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "gait_command.hpp"
#include "option_checks.hpp"
#include "subcommand.hpp"
#include "walk_as_robot.hpp"

namespace animrt::cli {
namespace {

struct MeasureArgs {
  std::string gait;
  std::string physics;
  int seeds = 10;
  double perturb_deg = 0.5;
  double settle_s = 0.5;
  int warmup_cycles = 1;
  int measure_cycles = 3;
  // Unset: every physics step and at once, or as the robot's IMU reports.
  std::optional<double> balance_delay_ms;
  std::optional<double> balance_period_ms;
  std::string robot;  // play as this robot file's figure plays (walk_as_robot.hpp)
};

struct Stat {
  double sum = 0.0, sum_sq = 0.0;
  int n = 0;
  void add(double x) {
    sum += x;
    sum_sq += x * x;
    ++n;
  }
  double mean() const { return n > 0 ? sum / n : 0.0; }
  double sd() const {
    if (n < 2) return 0.0;
    const double m = mean();
    return std::sqrt(std::max(0.0, (sum_sq - n * m * m) / (n - 1)));
  }
};

int run_measure(const MeasureArgs& a) {
  const GaitFile gait = load_gait_file(a.gait);
  sim::MujocoGaitSimulatorFactory factory(a.physics);
  auto simulator = factory.make();
  const double h = simulator->info().hip_height_m;
  const double f = gait.stride_frequency();

  evolve::WalkSettings settings;
  settings.settle_s = a.settle_s;
  settings.warmup_cycles = a.warmup_cycles;
  settings.measure_cycles = a.measure_cycles;
  settings.perturb_rad = a.perturb_deg * M_PI / 180.0;
  if (!a.robot.empty()) walk_as_robot(a.robot, simulator->info(), settings);
  if (a.balance_delay_ms) settings.balance_delay_s = *a.balance_delay_ms / 1000.0;
  if (a.balance_period_ms) settings.balance_period_s = *a.balance_period_ms / 1000.0;

  std::printf("walking %s on %s: %d starts, %.2f Hz, hip height %.3f m\n", a.gait.c_str(),
              a.physics.c_str(), a.seeds, f, h);
  if (!a.robot.empty()) {
    std::printf("targets played through %s's joint limits at %g Hz\n", a.robot.c_str(),
                1.0 / settings.limits_period_s);
  }
  if (gait.balance) {
    std::printf(
        "balance reflex: tilt_m %g, tilt_rate_m_s %g (legs on the ground stretch up to %g m)\n",
        gait.balance->tilt_m, gait.balance->tilt_rate_m_s, kMaxBalanceStretchM);
    if (settings.balance_delay_s > 0.0) {
      std::printf("balance reflex reads the trunk's attitude %g ms late\n",
                  settings.balance_delay_s * 1000.0);
    }
    if (settings.balance_period_s > 0.0) {
      std::printf("balance reflex reads the trunk's attitude every %g ms\n",
                  settings.balance_period_s * 1000.0);
    }
  }
  std::printf("%5s %6s %9s %9s %8s %9s %10s\n", "start", "fell", "fall s", "m/s", "stride m",
              "duty", "J/cycle");
  Stat speed, stride, duty, energy;
  int falls = 0;
  for (int s = 0; s < a.seeds; ++s) {
    settings.perturb_seed = static_cast<std::uint64_t>(s) + 1;
    const evolve::GaitMeasures m = simulator->walk(gait, settings);
    if (m.fell) {
      ++falls;
      std::printf("%5d %6s %9.2f\n", s + 1, "yes", m.sim_time - settings.settle_s);
      continue;
    }
    speed.add(m.speed);
    stride.add(m.stride_length);
    duty.add(m.duty_factor);
    energy.add(m.energy_per_cycle);
    std::printf("%5d %6s %9s %9.3f %8.3f %9.3f %10.1f\n", s + 1, "no", "-", m.speed,
                m.stride_length, m.duty_factor, m.energy_per_cycle);
  }
  std::printf("falls: %d of %d\n", falls, a.seeds);
  if (speed.n > 0) {
    std::printf("walks: speed %.3f (sd %.3f) m/s, stride %.3f (sd %.3f) m, duty %.3f (sd %.3f)\n",
                speed.mean(), speed.sd(), stride.mean(), stride.sd(), duty.mean(), duty.sd());
    std::printf("       speed / stride frequency = %.3f m\n", speed.mean() / f);
  }
  if (gait.froude) {
    const evolve::GaitTargets t = evolve::froude_targets(gait.froude->number, h);
    std::printf("Froude %.3f predicts: speed %.3f m/s, stride %.3f m, duty %.3f, %.2f Hz\n",
                gait.froude->number, t.speed, t.stride_length, t.duty_factor, t.stride_frequency);
  }
  return 0;
}

}  // namespace

void add_gait_measure_command(CLI::App& gait) {
  auto args = std::make_shared<MeasureArgs>();
  auto* cmd = gait.add_subcommand(
      "measure", "Walk a gait file on MuJoCo from perturbed starts: falls, speed, stride, duty");
  cmd->add_option("GAIT", args->gait, "gait file whose joints are the model's")->required();
  cmd->add_option("--physics", args->physics, "MuJoCo MJCF model to walk on")->required();
  cmd->add_option("--starts", args->seeds, "walks, each from its own perturbed start")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--perturb-deg", args->perturb_deg,
                  "each joint starts off its standing angle by up to this much")
      ->check(FiniteRange(0.0, 10.0));
  cmd->add_option("--settle", args->settle_s, "seconds standing before the walk")
      ->check(FiniteRange(0.0, 10.0));
  cmd->add_option("--warmup-cycles", args->warmup_cycles, "stride cycles walked, not measured")
      ->check(CLI::Range(0, 100));
  cmd->add_option("--measure-cycles", args->measure_cycles, "stride cycles measured")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--balance-delay-ms", args->balance_delay_ms,
                  "the balance reflex reads the trunk's attitude this late (a robustness "
                  "measure; the fitness reads it at once)")
      ->check(FiniteRange(0.0, 200.0));
  cmd->add_option("--balance-period-ms", args->balance_period_ms,
                  "the balance reflex reads the trunk's attitude once every this long, as from "
                  "an IMU reporting at that rate (a measure; the fitness reads it every step)")
      ->check(FiniteRange(0.0, 200.0));
  cmd->add_option("--robot", args->robot,
                  "play the targets through this robot file's joint velocity, acceleration and "
                  "position limits at its loop rate, as `animrt run` does (its joints named as "
                  "the model's); with an IMU in its imus:, the reflex reads the attitude at the "
                  "part's report period and latency unless the --balance options say otherwise")
      ->check(CLI::ExistingFile);
  set_subcommand_body(cmd, [args] { return run_measure(*args); });
}

}  // namespace animrt::cli
