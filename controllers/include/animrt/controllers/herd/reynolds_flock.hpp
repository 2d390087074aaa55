#pragma once
// The second flocking variant: Reynolds' rules as a weighted sum, following
// a wandering target.
//
// Per step and member i at p with walked velocity v:
//   steer = center_weight     * (flock centre - p)           cohesion
//         + velocity_weight   * (flock mean velocity - v)    alignment
//         + separation_weight * sum r/|r|^2                  separation
//         + follow_weight     * (target - p)                 follow
//         + randomize_weight  * a random unit vector
// where centre and mean velocity are over the group's members and r = p -
// p_j runs over every agent of the herd (any group) closer than
// separation_radius. The desired velocity is steer*dt (or v when that is
// zero), its length clamped to [min_velocity, max_velocity] (along the
// heading when it would be zero).
//
// Units: metres, seconds; velocities m/s. Because the velocity is steer*dt,
// the weights are tuned for one step length; the defaults are the text's,
// for birds at 1-8 m/s, and separation_radius is ours (the text sums over
// every boid; 1/|r| from farther than 10 m is a small fraction of the other
// terms at that scale).

#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"
#include "animrt/controllers/herd/boid.hpp"
#include "animrt/controllers/herd/spatial_grid.hpp"
#include "animrt/controllers/herd/wander_leader.hpp"

namespace animrt::herd {

struct ReynoldsFlockParams {
  double min_velocity = 1.0;  // m/s
  double max_velocity = 8.0;  // m/s
  int flock_size = 20;        // members the scene creates; steering uses the actual member count
  double center_weight = 1.0;
  double velocity_weight = 1.0;
  double separation_weight = 1.0;
  double follow_weight = 1.0;
  double randomize_weight = 1.0;
  double separation_radius = 10.0;  // m, cutoff of the separation sum
};

// Throws std::invalid_argument for a negative or non-finite value,
// min_velocity > max_velocity or flock_size < 0.
void validate(const ReynoldsFlockParams& p);

class ReynoldsFlock : public GroupSteering {
 public:
  // As UnityFlock: `seed` fixes the random vectors; space for a herd of
  // max(herd_capacity, max member + 1) agents is reserved.
  ReynoldsFlock(std::vector<int> members, const ReynoldsFlockParams& params, WanderLeader target,
                std::uint64_t seed, std::size_t herd_capacity = 0);

  std::span<const int> members() const override { return members_; }
  // Steers toward the target as it stands at t, then moves the target by dt.
  void steer(double t, double dt, std::span<const Agent> agents, std::span<Vec2> desired) override;

  const WanderLeader& leader() const { return target_; }
  const ReynoldsFlockParams& params() const { return params_; }
  void set_neighbour_search(NeighbourSearch s) { search_ = s; }

 private:
  std::vector<int> members_;
  ReynoldsFlockParams params_;
  WanderLeader target_;
  std::mt19937_64 rng_;
  NeighbourSearch search_ = NeighbourSearch::grid;
  SpatialGrid grid_;
  std::vector<Vec2> velocity_;  // scratch: each member's velocity, in member order
};

}  // namespace animrt::herd
