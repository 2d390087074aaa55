#include "animrt/controllers/herd/wander_leader.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace animrt::herd {

double angle_diff(double a, double b) {
  double d = std::remainder(a - b, 2.0 * std::numbers::pi);
  if (d <= -std::numbers::pi) d += 2.0 * std::numbers::pi;
  return d;
}

WanderLeader::WanderLeader(const WanderParams& params, Vec2 start, double heading,
                           std::uint64_t seed)
    : params_(params), pos_(start), heading_(heading), rng_(seed) {
  const Rect& w = params.wander_m;
  if (!(params.speed >= 0.0) || !(params.turn_gain >= 0.0) || !(params.max_turn >= 0.0) ||
      !(params.reach_m >= 0.0))
    throw std::invalid_argument("WanderLeader: speed, turn gain, max turn and reach must be >= 0");
  if (!std::isfinite(w.xmin) || !std::isfinite(w.xmax) || !std::isfinite(w.ymin) ||
      !std::isfinite(w.ymax) || w.xmax < w.xmin || w.ymax < w.ymin)
    throw std::invalid_argument("WanderLeader: wander rectangle must be finite with min <= max");
  next_goal();
}

void WanderLeader::next_goal() {
  const Rect& w = params_.wander_m;
  goal_.x = w.xmin + (w.xmax - w.xmin) * unit_uniform(rng_);
  goal_.y = w.ymin + (w.ymax - w.ymin) * unit_uniform(rng_);
  ++goals_drawn_;
}

void WanderLeader::step(double dt) {
  if (!(dt > 0.0)) return;
  pos_ += heading_vector(heading_) * (params_.speed * dt);
  const Vec2 to_goal = goal_ - pos_;
  if (norm2(to_goal) > 0.0) {
    // A slerp of the heading toward the goal's bearing by the fraction
    // gain*dt turns by that fraction of the angle between them.
    const double err = angle_diff(std::atan2(to_goal.y, to_goal.x), heading_);
    const double cap = params_.max_turn * dt;
    const double turn = std::clamp(err * std::min(1.0, params_.turn_gain * dt), -cap, cap);
    heading_ = std::remainder(heading_ + turn, 2.0 * std::numbers::pi);
  }
  if (norm(goal_ - pos_) <= params_.reach_m) next_goal();
}

}  // namespace animrt::herd
