#include "animrt/controllers/herd/unity_flock.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace animrt::herd {

void validate(const UnityFlockParams& p) {
  const std::pair<const char*, double> fields[] = {
      {"min_speed", p.min_speed},
      {"turn_speed", p.turn_speed},
      {"random_freq", p.random_freq},
      {"random_force", p.random_force},
      {"to_origin_force", p.to_origin_force},
      {"to_origin_range", p.to_origin_range},
      {"gravity", p.gravity},
      {"avoidance_radius", p.avoidance_radius},
      {"avoidance_force", p.avoidance_force},
      {"follow_velocity", p.follow_velocity},
      {"follow_radius", p.follow_radius},
      {"max_length_delta", p.max_length_delta},
  };
  for (const auto& [name, v] : fields)
    if (!(v >= 0.0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("UnityFlock: ") + name + " must be finite and >= 0");
  if (!(p.to_origin_range > 0.0))
    throw std::invalid_argument("UnityFlock: to_origin_range must be > 0");
}

UnityFlock::UnityFlock(std::vector<int> members, const UnityFlockParams& params,
                       WanderLeader leader, std::uint64_t seed, std::size_t herd_capacity)
    : members_(std::move(members)), params_(params), leader_(leader), rng_(seed) {
  validate(params_);
  check_members(members_, "UnityFlock");
  grid_.reserve(std::max(herd_capacity, herd_size_needed(members_)));
  push_.assign(members_.size(), Vec2{});
  next_renewal_.assign(members_.size(), -std::numeric_limits<double>::infinity());
  velocity_.assign(members_.size(), Vec2{});
  slot_of_.assign(herd_size_needed(members_), -1);
  for (std::size_t k = 0; k < members_.size(); ++k)
    slot_of_[static_cast<std::size_t>(members_[k])] = static_cast<int>(k);
}

Vec2 UnityFlock::boid_direction(int j, const Agent& b) const {
  const auto u = static_cast<std::size_t>(j);
  if (started_ && u < slot_of_.size() && slot_of_[u] >= 0) {
    const Vec2 v = velocity_[static_cast<std::size_t>(slot_of_[u])];
    if (norm2(v) > 0.0) return normalized(v);
  }
  return motion_direction(b);
}

void UnityFlock::steer(double t, double dt, std::span<const Agent> agents,
                       std::span<Vec2> desired) {
  if (agents.size() < herd_size_needed(members_) || desired.size() < agents.size())
    throw std::invalid_argument("UnityFlock: the herd is smaller than the flock's member indices");
  const UnityFlockParams& p = params_;
  const std::size_t n = members_.size();
  const bool use_grid = search_ == NeighbourSearch::grid && p.follow_radius > 0.0;
  if (use_grid) grid_.build(agents, p.follow_radius);

  Vec2 sum_pos;
  for (const int i : members_) sum_pos += agents[static_cast<std::size_t>(i)].position;
  const double others = static_cast<double>(n > 0 ? n - 1 : 0);
  const Vec2 leader_pos = leader_.position();
  // The text's boids are children of the controller: its move this step
  // carries them, and their own velocity is on top of it.
  const Vec2 carried = leader_.velocity();

  for (std::size_t k = 0; k < n; ++k) {
    const int i = members_[k];
    const Agent& a = agents[static_cast<std::size_t>(i)];
    const Vec2 pos = a.position;

    // The boid's own velocity, as the text's boid keeps it: a figure that
    // stands (blocked, or asked for less than its slowest walk) does not
    // reset it, so the flock's pull builds up until the figure walks again.
    Vec2 v = started_ ? velocity_[k] : a.velocity();
    if (norm(v) < p.min_speed) v = boid_direction(i, a) * p.min_speed;

    // Separation from every agent, alignment with the own group's, inside
    // follow_radius.
    Vec2 avg_vel;
    const auto neighbour = [&](int j, double d2) {
      const double d = std::sqrt(d2);
      if (!(d < p.follow_radius)) return;
      const Agent& b = agents[static_cast<std::size_t>(j)];
      if (d < p.avoidance_radius && d > 0.0)
        avg_vel += (pos - b.position) * ((1.0 - d / p.avoidance_radius) * p.avoidance_force / d);
      if (b.group == a.group)
        avg_vel += boid_direction(j, b) * (d / p.follow_radius * p.follow_velocity);
    };
    if (use_grid) {
      grid_.for_each_near(i, p.follow_radius, neighbour);
    } else if (p.follow_radius > 0.0) {
      for (std::size_t j = 0; j < agents.size(); ++j)
        if (static_cast<int>(j) != i)
          neighbour(static_cast<int>(j), norm2(agents[j].position - pos));
    }

    Vec2 to_avg;
    if (others > 0.0) {
      avg_vel = avg_vel / others;
      to_avg = (sum_pos - pos) / others - pos;
    }

    const Vec2 to_leader = leader_pos - pos;
    const Vec2 origin_push = to_leader * (p.to_origin_force / p.to_origin_range);

    if (t >= next_renewal_[k]) {
      push_[k] = random_in_unit_disc(rng_) * p.random_force;
      next_renewal_[k] = p.random_freq > 0.0 ? t + (0.5 + unit_uniform(rng_)) / p.random_freq
                                             : std::numeric_limits<double>::infinity();
    }

    Vec2 wanted = v - v * dt;
    wanted += (push_[k] + origin_push + avg_vel + normalized(to_avg) * p.gravity) * dt;

    Vec2 out = rotate_towards(v, wanted, p.turn_speed * dt, p.max_length_delta);
    if (norm(out) < p.min_speed) {
      const Vec2 u = norm2(out) > 0.0 ? normalized(out) : normalized(v);
      out = (norm2(u) > 0.0 ? u : heading_vector(a.heading)) * p.min_speed;
    }
    desired[static_cast<std::size_t>(i)] = out;
  }
  for (std::size_t k = 0; k < n; ++k) {
    Vec2& d = desired[static_cast<std::size_t>(members_[k])];
    velocity_[k] = d;
    d += carried;
  }
  started_ = true;
  leader_.step(dt);
}

}  // namespace animrt::herd
