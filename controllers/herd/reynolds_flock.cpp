#include "animrt/controllers/herd/reynolds_flock.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace animrt::herd {

void validate(const ReynoldsFlockParams& p) {
  const std::pair<const char*, double> fields[] = {
      {"min_velocity", p.min_velocity},           {"max_velocity", p.max_velocity},
      {"center_weight", p.center_weight},         {"velocity_weight", p.velocity_weight},
      {"separation_weight", p.separation_weight}, {"follow_weight", p.follow_weight},
      {"randomize_weight", p.randomize_weight},   {"separation_radius", p.separation_radius},
  };
  for (const auto& [name, v] : fields)
    if (!(v >= 0.0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("ReynoldsFlock: ") + name +
                                  " must be finite and >= 0");
  if (p.min_velocity > p.max_velocity)
    throw std::invalid_argument("ReynoldsFlock: min_velocity must not exceed max_velocity");
  if (p.flock_size < 0) throw std::invalid_argument("ReynoldsFlock: flock_size must be >= 0");
}

ReynoldsFlock::ReynoldsFlock(std::vector<int> members, const ReynoldsFlockParams& params,
                             WanderLeader target, std::uint64_t seed, std::size_t herd_capacity)
    : members_(std::move(members)), params_(params), target_(target), rng_(seed) {
  validate(params_);
  check_members(members_, "ReynoldsFlock");
  grid_.reserve(std::max(herd_capacity, herd_size_needed(members_)));
  velocity_.resize(members_.size());
}

void ReynoldsFlock::steer(double /*t*/, double dt, std::span<const Agent> agents,
                          std::span<Vec2> desired) {
  if (agents.size() < herd_size_needed(members_) || desired.size() < agents.size())
    throw std::invalid_argument(
        "ReynoldsFlock: the herd is smaller than the flock's member indices");
  const ReynoldsFlockParams& p = params_;
  const std::size_t n = members_.size();
  const double rs = p.separation_radius;
  const bool use_grid = search_ == NeighbourSearch::grid && rs > 0.0;
  if (use_grid) grid_.build(agents, rs);

  Vec2 center, flock_vel;
  for (std::size_t k = 0; k < n; ++k) {
    const Agent& a = agents[static_cast<std::size_t>(members_[k])];
    velocity_[k] = a.velocity();
    center += a.position;
    flock_vel += velocity_[k];
  }
  if (n > 0) {
    center = center / static_cast<double>(n);
    flock_vel = flock_vel / static_cast<double>(n);
  }
  const Vec2 target = target_.position();

  for (std::size_t k = 0; k < n; ++k) {
    const int i = members_[k];
    const Agent& a = agents[static_cast<std::size_t>(i)];
    const Vec2 pos = a.position;
    const Vec2 v = velocity_[k];

    // Coincident agents give no direction apart and are skipped.
    Vec2 separation;
    const auto push = [&](int j, double d2) {
      if (d2 > 0.0 && d2 < rs * rs)
        separation += (pos - agents[static_cast<std::size_t>(j)].position) / d2;
    };
    if (use_grid) {
      grid_.for_each_near(i, rs, push);
    } else if (rs > 0.0) {
      for (std::size_t j = 0; j < agents.size(); ++j)
        if (static_cast<int>(j) != i) push(static_cast<int>(j), norm2(agents[j].position - pos));
    }

    const Vec2 steer = p.center_weight * (center - pos) + p.velocity_weight * (flock_vel - v) +
                       p.separation_weight * separation + p.follow_weight * (target - pos) +
                       p.randomize_weight * random_unit_vector(rng_);

    Vec2 vel = steer * dt;
    if (norm2(vel) == 0.0) vel = v;
    const double speed = norm(vel);
    if (speed > p.max_velocity) {
      vel = vel * (p.max_velocity / speed);
    } else if (speed < p.min_velocity) {
      vel = (speed > 0.0 ? vel / speed : heading_vector(a.heading)) * p.min_velocity;
    }
    desired[static_cast<std::size_t>(i)] = vel;
  }
  target_.step(dt);
}

}  // namespace animrt::herd
