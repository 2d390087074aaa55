// Walking a gait on a MuJoCo model and measuring it (see mujoco_gait_sim.hpp).

#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

#include "animrt/controllers/gait/balance_reflex.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/core/safety_filter.hpp"
#include "animrt/sim/mujoco/foot_meter.hpp"
#include "animrt/sim/mujoco/mujoco_leg_model.hpp"
#include "animrt/sim/mujoco/mujoco_walk.hpp"

namespace animrt::sim {
namespace {

int root_qpos(const mjModel* m, int torso) {
  const int j = m->body_jntadr[torso];
  return (j >= 0 && m->jnt_type[j] == mjJNT_FREE) ? m->jnt_qposadr[j] : -1;
}

// The gait's balance reflex (balance_reflex.hpp) on the physics: the trunk's
// tilt and the legs (which feet touch something, their Jacobians along the
// trunk's vertical) measured on the walk's data, the stretch added to the
// actuator targets by the same apply_balance() the runtime plays.
class LegBalance {
 public:
  // The reflex reads the tilt `delay_steps` physics steps old, once every
  // `period_steps` steps (an IMU's reports), and holds it between.
  LegBalance(const MujocoModel& mm, const mjData* d, const GaitBalance& gains, long delay_steps,
             long period_steps)
      : mm_(mm),
        period_(static_cast<std::size_t>(std::max(1L, period_steps))),
        reflex_(gains),
        legs_(mm, d),
        scratch_(2 * legs_.max_leg_joints(), 0.0),
        tilts_(static_cast<std::size_t>(delay_steps) + 1) {}

  // Adds the reflex to the actuator targets already in d->ctrl.
  void apply(mjData* d, double dt) {
    const double* r = d->xmat + 9 * mm_.torso_body;
    // World z of the trunk's forward and left axes; until the delay has
    // passed, the first tilt (the figure stood still before).
    const TrunkTilt now{r[6], r[7]};
    if (steps_ == 0) std::fill(tilts_.begin(), tilts_.end(), now);
    tilts_[steps_ % tilts_.size()] = now;
    ++steps_;
    if ((steps_ - 1) % period_ == 0) {
      reflex_.update(tilts_[steps_ % tilts_.size()], dt * static_cast<double>(period_));
    }
    legs_.pose({}, {});
    apply_balance(reflex_, legs_,
                  std::span<double>(d->ctrl, static_cast<std::size_t>(mm_.model->nu)), scratch_);
  }

 private:
  const MujocoModel& mm_;
  std::size_t period_;
  BalanceReflex reflex_;
  MujocoLegModel legs_;
  std::vector<double> scratch_;
  std::vector<TrunkTilt> tilts_;  // ring: the newest at (steps_ - 1), the one read at steps_
  std::size_t steps_ = 0;
};

// The runtime's safety filter between the walk's targets and the actuators
// (WalkSettings::joint_limits): stepped once a loop period from the standing
// pose at rest, its command held between steps as a servo holds its goal.
class LimitedTargets {
 public:
  LimitedTargets(const std::vector<JointLimits>& limits, double period, const double* standing)
      : filter_(limits, period),
        period_(period),
        targets_(limits.size(), 0.0),
        commands_(standing, standing + limits.size()) {
    filter_.reset(commands_);
  }

  // `ctrl` holds this step's targets; it leaves with the filter's command.
  void apply(double t, double* ctrl) {
    if (t + 1e-9 >= next_s_) {
      std::copy(ctrl, ctrl + targets_.size(), targets_.begin());
      filter_.step(targets_, commands_);
      next_s_ += period_;
    }
    std::copy(commands_.begin(), commands_.end(), ctrl);
  }

 private:
  SafetyFilter filter_;
  double period_;
  double next_s_ = 0.0;
  std::vector<double> targets_;
  std::vector<double> commands_;
};

}  // namespace

void place_standing(const MujocoModel& mm, mjData* d, const double* targets) {
  const mjModel* m = mm.model.get();
  mj_resetData(m, d);
  for (std::size_t a = 0; a < mm.actuator_qpos.size(); ++a) {
    const int j = m->actuator_trnid[2 * a];
    double q = targets[a];
    if (m->jnt_limited[j]) q = std::clamp(q, m->jnt_range[2 * j], m->jnt_range[2 * j + 1]);
    d->qpos[mm.actuator_qpos[a]] = q;
    d->ctrl[a] = q;
  }
  mj_kinematics(m, d);
  double lowest = 1e9;
  for (int g : mm.foot_geoms) {
    // Feet are spheres or boxes standing level: the bottom is centre - (radius | half height).
    const double below =
        m->geom_type[g] == mjGEOM_BOX ? m->geom_size[3 * g + 2] : m->geom_size[3 * g];
    lowest = std::min(lowest, d->geom_xpos[3 * g + 2] - below);
  }
  const int root = root_qpos(m, mm.torso_body);
  if (root >= 0) d->qpos[root + 2] -= lowest - 0.001;
  mj_forward(m, d);
}

bool has_fallen(const MujocoModel& mm, const mjData* d, double standing_z) {
  const double z = d->xpos[3 * mm.torso_body + 2];
  const double up = d->xmat[9 * mm.torso_body + 8];  // z component of the torso's z axis
  if (!std::isfinite(z) || !std::isfinite(up)) return true;
  if (d->warning[mjWARN_BADQACC].number > 0 || d->warning[mjWARN_BADQPOS].number > 0 ||
      d->warning[mjWARN_BADQVEL].number > 0) {
    return true;
  }
  if (z < 0.5 * standing_z || up < 0.5) return true;
  // The trunk on the ground: a figure whose legs fold under it can rest on
  // its belly above half its standing height (the horse, whose trunk hangs
  // between its legs). Only a contact between a trunk geom and a geom of the
  // world body counts; the trunk touching the figure's own legs is no fall.
  const mjModel* m = mm.model.get();
  for (int c = 0; c < d->ncon; ++c) {
    const int b1 = m->geom_bodyid[d->contact[c].geom1];
    const int b2 = m->geom_bodyid[d->contact[c].geom2];
    if ((b1 == mm.torso_body && b2 == 0) || (b2 == mm.torso_body && b1 == 0)) return true;
  }
  return false;
}

MujocoGaitSimulator::MujocoGaitSimulator(std::shared_ptr<const MujocoModel> model)
    : model_(std::move(model)), data_(make_mujoco_data(*model_)) {
  info_.joints = model_->actuated_joints;
  info_.hip_height_m = model_->hip_height_m;
  info_.mass_kg = model_->mass_kg;
}

evolve::GaitMeasures MujocoGaitSimulator::walk(const GaitFile& gait,
                                               const evolve::WalkSettings& settings) {
  const MujocoModel& mm = *model_;
  const mjModel* m = mm.model.get();
  mjData* d = data_.get();
  const auto specs = model_joint_specs(mm);
  const auto source = make_gait_source(gait, specs);
  std::vector<double> targets(specs.size(), 0.0);
  evolve::GaitMeasures out;

  // Standing pose: every joint at its mean over one stride (all feet down).
  const double f = gait.stride_frequency();
  std::vector<double> stand(specs.size(), 0.0);
  constexpr int kMeanSamples = 64;
  for (int i = 0; i < kMeanSamples; ++i) {
    source->sample(static_cast<double>(i) / (kMeanSamples * f), targets);
    for (std::size_t a = 0; a < targets.size(); ++a) stand[a] += targets[a] / kMeanSamples;
  }
  if (settings.perturb_seed != 0 && settings.perturb_rad > 0.0) {
    // The standing pose itself is perturbed, so the feet are still placed on
    // the floor and the blend into the gait starts from where the joints are.
    std::mt19937_64 rng(settings.perturb_seed);
    std::uniform_real_distribution<double> jitter(-settings.perturb_rad, settings.perturb_rad);
    for (double& q : stand) q += jitter(rng);
  }
  place_standing(mm, d, stand.data());
  const double dt = m->opt.timestep;
  const auto steps_for = [dt](double s) { return static_cast<long>(std::llround(s / dt)); };
  const long settle = steps_for(settings.settle_s);
  const long warmup = steps_for(settings.warmup_cycles / f);
  const long measure = steps_for(settings.measure_cycles / f);
  // From standing into the gait: blended in over the first cycle (smoothstep).
  const long blend = std::max(1L, std::min(warmup, steps_for(1.0 / f)));
  const double standing_z = d->xpos[3 * mm.torso_body + 2];
  std::optional<LegBalance> balance;
  if (gait.balance)
    balance.emplace(mm, d, *gait.balance, steps_for(settings.balance_delay_s),
                    steps_for(settings.balance_period_s));
  std::optional<LimitedTargets> limited;
  if (!settings.joint_limits.empty()) {
    if (settings.joint_limits.size() != static_cast<std::size_t>(m->nu) ||
        !(settings.limits_period_s > 0.0)) {
      throw std::invalid_argument("walk: one joint limit per actuator and a period > 0 needed");
    }
    limited.emplace(settings.joint_limits, settings.limits_period_s, d->ctrl);
  }

  FootMeter feet(mm, dt, f);
  double energy = 0.0;
  double max_tilt = 0.0;  // rad
  double x0 = 0.0;

  const long total = settle + warmup + measure;
  for (long step = 0; step < total; ++step) {
    const bool walking = step >= settle;
    if (walking) {
      const long k = step - settle;
      source->sample(static_cast<double>(k) * dt, targets);
      const double u = std::min(1.0, static_cast<double>(k) / static_cast<double>(blend));
      const double s = u * u * (3.0 - 2.0 * u);
      for (std::size_t a = 0; a < targets.size(); ++a) {
        d->ctrl[a] = stand[a] + s * (targets[a] - stand[a]);
      }
      if (balance) balance->apply(d, dt);
    }
    if (limited) limited->apply(static_cast<double>(step) * dt, d->ctrl);
    mj_step(m, d);
    ++out.steps;
    if (has_fallen(mm, d, standing_z)) {
      out.fell = true;
      break;
    }
    if (step == settle + warmup - 1) x0 = d->xpos[3 * mm.torso_body];
    if (step < settle + warmup) continue;

    feet.step(d, static_cast<double>(step) * dt);
    for (int a = 0; a < m->nu; ++a) {
      energy += std::fabs(d->actuator_force[a] * d->actuator_velocity[a]) * dt;
    }
    const double up = std::clamp(d->xmat[9 * mm.torso_body + 8], -1.0, 1.0);
    max_tilt = std::max(max_tilt, std::acos(up));
  }
  out.sim_time = static_cast<double>(out.steps) * dt;
  if (out.fell) return out;

  const double window = static_cast<double>(measure) * dt;
  out.distance = d->xpos[3 * mm.torso_body] - x0;
  out.speed = out.distance / window;
  out.duty_factor = feet.duty_factor();
  out.stride_length = feet.stride_length_m();
  out.energy_per_cycle = energy / settings.measure_cycles;
  out.max_tilt_deg = max_tilt * 180.0 / M_PI;
  return out;
}

MujocoGaitSimulatorFactory::MujocoGaitSimulatorFactory(const std::string& model_path)
    : model_(std::make_shared<const MujocoModel>(load_mujoco_model(model_path))) {}

std::unique_ptr<evolve::GaitSimulator> MujocoGaitSimulatorFactory::make() const {
  return std::make_unique<MujocoGaitSimulator>(model_);
}

}  // namespace animrt::sim
