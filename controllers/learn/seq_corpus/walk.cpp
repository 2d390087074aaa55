// Walking one configuration and skinning every frame (see generator.hpp).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "animrt/controllers/gait/froude.hpp"
#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/learn/seq_corpus/generator.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "animrt/sim/mujoco/mujoco_walk.hpp"

namespace animrt::learn::seq_corpus {

using sim::has_fallen;
using sim::model_joint_specs;
using sim::place_standing;
namespace {

// Noise of a seed (relative Froude number, settling range in seconds).
constexpr double kFroudeJitter = 0.02;
// Start phase in stride cycles.
constexpr double kPhaseJitter = 0.1;
constexpr double kSettleMinS = 0.4;
constexpr double kSettleRangeS = 0.2;

// SplitMix64: a small generator whose stream is the same on every platform.
struct SplitMix {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

double torso_yaw(const MujocoModel& mm, const mjData* d) {
  const double* r = d->xmat + 9 * mm.torso_body;
  return std::atan2(r[3], r[0]);  // the body's x axis on the ground plane
}

}  // namespace

WalkTiming draw_timing(const WalkConfig& config) {
  SplitMix rng{config.seed};
  WalkTiming t;
  t.froude = config.froude * (1.0 + kFroudeJitter * (2.0 * rng.uniform() - 1.0));
  t.start_phase = kPhaseJitter * rng.uniform();
  t.settle_s = kSettleMinS + kSettleRangeS * rng.uniform();
  return t;
}

Skin bind_pose_skin(const MujocoModel& model, int target_vertices) {
  MujocoData data = make_mujoco_data(model);
  const std::vector<double> zero(model.actuated_joints.size(), 0.0);
  place_standing(model, data.get(), zero.data());
  return build_skin(model.model.get(), data.get(), SkinOptions{target_vertices});
}

long physics_steps_per_frame(const MujocoModel& mm, const WalkOptions& options) {
  const double dt = mm.model->opt.timestep;
  if (options.frames < 1) throw std::invalid_argument("frames must be at least 1");
  const double per_frame = 1.0 / (options.fps * dt);
  const long steps = std::lround(per_frame);
  if (!(options.fps > 0.0) || steps < 1 ||
      std::fabs(per_frame - static_cast<double>(steps)) > 1e-6) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "frame rate %g fps: 1/fps must be a whole number of physics steps of %g s",
                  options.fps, dt);
    throw std::invalid_argument(text);
  }
  return steps;
}

WalkRecord walk_sequence(const MujocoModel& mm, const Skin& skin, const WalkConfig& config,
                         const WalkOptions& options) {
  const mjModel* m = mm.model.get();
  const double dt = m->opt.timestep;
  if (options.frames < 1) throw std::invalid_argument("frames must be at least 1");
  const long steps_per_frame = physics_steps_per_frame(mm, options);
  if (!(config.froude > 0.0)) throw std::invalid_argument("Froude number must be positive");
  if (skin.bind_pos.size() != static_cast<std::size_t>(m->nbody))
    throw std::invalid_argument("the skin was made for another model");

  WalkRecord out;
  out.config = config;
  out.timing = draw_timing(config);
  GaitFile gait = load_gait_file(config.gait_file);
  const double hip = gait.froude ? gait.froude->hip_height_m : mm.hip_height_m;
  gait.stride_frequency_hz.reset();
  gait.froude = FroudeTiming{out.timing.froude, hip};
  const double speed = froude_velocity(out.timing.froude, hip);
  if (gait.steering) {
    // The walk's speed joins a steerable gait's walking range: a command
    // below its slowest walk would stop the figure, above its fastest would
    // be cut to it. The 0.1 % margins keep the speed inside after rounding.
    GaitSteering& range = *gait.steering;
    const double fr = speed / std::sqrt(kStandardGravity * range.hip_height_m);
    range.min_froude = std::min(range.min_froude, 0.999 * fr);
    range.max_froude = std::max(range.max_froude, 1.001 * fr);
  }
  const auto specs = model_joint_specs(mm);
  const auto source =
      options.make_source ? options.make_source(gait, specs) : make_gait_source(gait, specs);
  source->steer(MotionCommand{speed, config.turn_rad_s});
  const double f = gait.stride_frequency();

  MujocoData data = make_mujoco_data(mm);
  mjData* d = data.get();
  const std::size_t nu = specs.size();
  std::vector<double> targets(nu, 0.0), stand(nu, 0.0);
  // Standing pose: every joint at its mean over one stride (all feet down).
  constexpr int kMeanSamples = 64;
  for (int i = 0; i < kMeanSamples; ++i) {
    source->sample(static_cast<double>(i) / (kMeanSamples * f), targets);
    for (std::size_t a = 0; a < nu; ++a) stand[a] += targets[a] / kMeanSamples;
  }
  place_standing(mm, d, stand.data());
  const double standing_z = d->xpos[3 * mm.torso_body + 2];
  const auto steps_for = [dt](double s) { return static_cast<long>(std::llround(s / dt)); };
  const long settle = steps_for(out.timing.settle_s);
  const long blend = std::max(1L, steps_for(1.0 / f));
  const long first_frame = settle + std::max(0L, steps_for(options.warmup_cycles / f));
  const long total = first_frame + steps_per_frame * (options.frames - 1) + 1;
  const double phase_s = out.timing.start_phase / f;

  out.mesh.clips.push_back({sequence_name(config), 0, 0, options.fps});
  out.mesh.triangles = skin.rest.triangles;
  double yaw_prev = 0.0, yaw_turns = 0.0;
  for (long step = 0; step < total; ++step) {
    if (step >= settle) {
      const long k = step - settle;
      source->sample(phase_s + static_cast<double>(k) * dt, targets);
      const double u = std::min(1.0, static_cast<double>(k) / static_cast<double>(blend));
      const double s = u * u * (3.0 - 2.0 * u);
      for (std::size_t a = 0; a < nu; ++a) d->ctrl[a] = stand[a] + s * (targets[a] - stand[a]);
    }
    // The frame is the state after `step` steps: frame 0 is where the walk
    // has gone through its warm-up.
    if (step >= first_frame && (step - first_frame) % steps_per_frame == 0) {
      seqnet::Positions p;
      pose_skin(skin, d, p);
      out.mesh.frames.push_back(std::move(p));
      out.time_s.push_back(static_cast<double>(step - first_frame) * dt);
      std::vector<double> q(nu);
      for (std::size_t a = 0; a < nu; ++a) q[a] = d->qpos[mm.actuator_qpos[a]];
      out.joints.push_back(std::move(q));
      out.qpos.emplace_back(d->qpos, d->qpos + m->nq);
      const double yaw = torso_yaw(mm, d);
      if (!out.torso.empty()) {
        const double jump = yaw - yaw_prev;
        if (jump > kPi) yaw_turns -= 2.0 * kPi;
        if (jump < -kPi) yaw_turns += 2.0 * kPi;
      }
      yaw_prev = yaw;
      const double* x = d->xpos + 3 * mm.torso_body;
      out.torso.push_back({x[0], x[1], x[2], yaw + yaw_turns});
      if (static_cast<int>(out.mesh.frames.size()) == options.frames) break;
    }
    mj_step(m, d);
    if (has_fallen(mm, d, standing_z)) {
      out.fell = true;
      break;
    }
  }
  out.mesh.clips.front().count = out.mesh.frame_count();
  if (out.torso.size() >= 2) {
    const auto& a = out.torso.front();
    const auto& b = out.torso.back();
    const double span = out.time_s.back() - out.time_s.front();
    out.speed_m_s = std::hypot(b[0] - a[0], b[1] - a[1]) / span;
    out.turn_rad_s = (b[3] - a[3]) / span;
  }
  return out;
}

}  // namespace animrt::learn::seq_corpus
