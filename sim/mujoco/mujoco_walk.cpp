// One commanded walk on a MuJoCo model (see mujoco_walk.hpp).

#include "animrt/sim/mujoco/mujoco_walk.hpp"

#include <cmath>
#include <random>

#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"

namespace animrt::sim {
namespace {

double torso_yaw(const MujocoModel& mm, const mjData* d) {
  const double* r = d->xmat + 9 * mm.torso_body;  // row-major, body to world
  return std::atan2(r[3], r[0]);                  // heading of the torso's x axis
}

}  // namespace

std::vector<JointSpec> model_joint_specs(const MujocoModel& mm) {
  const mjModel* m = mm.model.get();
  std::vector<JointSpec> specs;
  for (std::size_t a = 0; a < mm.actuated_joints.size(); ++a) {
    const int j = m->actuator_trnid[2 * a];
    JointSpec s;
    s.name = mm.actuated_joints[a];
    s.limits.min_position = m->jnt_limited[j] ? m->jnt_range[2 * j] : -kPi;
    s.limits.max_position = m->jnt_limited[j] ? m->jnt_range[2 * j + 1] : kPi;
    s.limits.max_velocity = 100.0;
    s.limits.max_acceleration = 10000.0;
    specs.push_back(s);
  }
  return specs;
}

WalkTrace walk_command(const MujocoModel& mm, MotionSource& source, const MotionCommand& command,
                       const WalkTrial& trial) {
  const mjModel* m = mm.model.get();
  MujocoData data = make_mujoco_data(mm);
  mjData* d = data.get();
  const auto nu = static_cast<std::size_t>(m->nu);
  std::vector<double> targets(nu, 0.0);
  WalkTrace out;

  source.steer(MotionCommand{0.0, 0.0});
  source.sample(0.0, targets);
  place_standing(mm, d, targets.data());
  if (trial.seed != 0) {
    std::mt19937_64 rng(trial.seed);
    std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
    for (std::size_t a = 0; a < nu; ++a) d->qpos[mm.actuator_qpos[a]] += jitter(rng);
    mj_forward(m, d);
  }
  const double standing_z = d->xpos[3 * mm.torso_body + 2];
  const double dt = m->opt.timestep;
  const auto steps_for = [dt](double s) { return static_cast<long>(std::llround(s / dt)); };
  const long settle = steps_for(trial.settle_s);
  const long warmup = steps_for(trial.warmup_s);
  const long total = settle + warmup + steps_for(trial.measure_s);
  const long every = std::max(1L, steps_for(trial.sample_period_s));

  double yaw = torso_yaw(mm, d), yaw_raw = yaw;
  double along = 0.0;  // distance along the heading over the measured time
  double x_prev = d->xpos[3 * mm.torso_body], y_prev = d->xpos[3 * mm.torso_body + 1];
  double yaw0 = 0.0;
  long measured = 0;
  for (long step = 0; step < total; ++step) {
    if (step == settle) source.steer(command);
    // Time runs from the first sample on, through the settle (standing).
    source.sample(static_cast<double>(step + 1) * dt, targets);
    for (std::size_t a = 0; a < nu; ++a) d->ctrl[a] = targets[a];
    mj_step(m, d);
    const double raw = torso_yaw(mm, d);
    yaw += std::remainder(raw - yaw_raw, 2.0 * kPi);
    yaw_raw = raw;
    const double x = d->xpos[3 * mm.torso_body], y = d->xpos[3 * mm.torso_body + 1];
    const double t = static_cast<double>(step - settle + 1) * dt;
    if (step >= settle + warmup) {
      if (step == settle + warmup) yaw0 = yaw;
      along += (x - x_prev) * std::cos(yaw) + (y - y_prev) * std::sin(yaw);
      ++measured;
    }
    x_prev = x;
    y_prev = y;
    if (step >= settle && (step - settle) % every == 0) out.samples.push_back({t, x, y, yaw});
    if (has_fallen(mm, d, standing_z)) {
      out.fell = true;
      out.fall_s = t;
      break;
    }
  }
  if (measured > 0) {
    const double window = static_cast<double>(measured) * dt;
    out.achieved.speed_m_s = along / window;
    out.achieved.turn_rad_s = (yaw - yaw0) / window;
  }
  return out;
}

}  // namespace animrt::sim
