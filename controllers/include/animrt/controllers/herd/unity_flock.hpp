#pragma once
// The first flocking variant: the boid of Unity's old Tropical Paradise
// sample, following a wandering controller point (the "origin").
//
// Per step and member, from where the figures stand:
//   v       the boid's own velocity (the desired velocity it gave in the
//           previous step; the figure's walked velocity at the first step),
//           raised to min_speed (along the heading when it is zero);
//   avg     over every agent within follow_radius (d < follow_radius):
//           separation (any group) closer than avoidance_radius,
//             (1 - d/avoidance_radius) * avoidance_force along the way apart,
//           alignment (own group only),
//             the neighbour's unit boid velocity (its walked one for an
//             agent of another flock) * d/follow_radius * follow_velocity,
//           divided by the number of other members of the group;
//   to_avg  toward the mean position of the other members (cohesion);
//   origin  toward the leader, |origin| = d/to_origin_range * to_origin_force;
//   push    a point of the unit disc * random_force, renewed after a random
//           interval uniform in [0.5, 1.5] / random_freq;
//   wanted  = v - v*dt + (push + origin + avg + unit(to_avg)*gravity) * dt;
// and the boid's new velocity is v turned toward wanted by at most
// turn_speed*dt (its length moved toward |wanted| by at most
// max_length_delta), never slower than min_speed. The text's boids are
// children of the controller, so the leader's move carries them: the
// figure is asked for the boid's velocity plus the leader's, and walks
// what its gait can of it; the boid's velocity is
// not reset to the figure's, as a figure that stands (its slowest walk is
// faster than the pull on it, or a neighbour blocks it) would otherwise
// give the rules nothing to build on and the flock would stay standing.
//
// Units: metres, seconds; the forces are accelerations (m/s^2), the speeds
// m/s, turn_speed rad/s. The defaults are the text's, for birds in a Unity
// scene; walking figures need much smaller ones (docs/herd.md).

#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"
#include "animrt/controllers/herd/boid.hpp"
#include "animrt/controllers/herd/spatial_grid.hpp"
#include "animrt/controllers/herd/wander_leader.hpp"

namespace animrt::herd {

struct UnityFlockParams {
  double min_speed = 20.0;          // m/s
  double turn_speed = 20.0;         // rad/s
  double random_freq = 20.0;        // 1/s, mean rate of renewing the random push
  double random_force = 20.0;       // m/s^2, radius of the random push's disc
  double to_origin_force = 50.0;    // m/s^2 at to_origin_range from the leader
  double to_origin_range = 100.0;   // m
  double gravity = 2.0;             // m/s^2 toward the members' mean position
  double avoidance_radius = 50.0;   // m
  double avoidance_force = 20.0;    // m/s^2 at zero distance
  double follow_velocity = 4.0;     // m/s^2 at follow_radius
  double follow_radius = 40.0;      // m, neighbours farther than this are not seen
  double max_length_delta = 100.0;  // m/s per step, RotateTowards' length limit (the text's 100)
};

// Throws std::invalid_argument for a negative or non-finite value, or a
// non-positive to_origin_range.
void validate(const UnityFlockParams& p);

class UnityFlock : public GroupSteering {
 public:
  // `members` index the herd's agents; `seed` fixes the random pushes. Space
  // for a herd of max(herd_capacity, max member + 1) agents is reserved, so
  // steer() on such a herd does not allocate.
  UnityFlock(std::vector<int> members, const UnityFlockParams& params, WanderLeader leader,
             std::uint64_t seed, std::size_t herd_capacity = 0);

  std::span<const int> members() const override { return members_; }
  // Steers toward the leader as it stands at t, then moves the leader by dt.
  void steer(double t, double dt, std::span<const Agent> agents, std::span<Vec2> desired) override;

  const WanderLeader& leader() const { return leader_; }
  const UnityFlockParams& params() const { return params_; }
  void set_neighbour_search(NeighbourSearch s) { search_ = s; }

 private:
  std::vector<int> members_;
  UnityFlockParams params_;
  WanderLeader leader_;
  std::mt19937_64 rng_;
  NeighbourSearch search_ = NeighbourSearch::grid;
  SpatialGrid grid_;
  std::vector<Vec2> push_;            // per member
  std::vector<double> next_renewal_;  // per member, s
  std::vector<Vec2> velocity_;        // per member: the boid's own velocity, m/s
  std::vector<int> slot_of_;          // agent index -> member slot, -1 for none
  bool started_ = false;              // velocity_ holds a step's output

  // Unit direction of agent j's boid velocity when it is a member of this
  // flock that has one; else the way its figure moves.
  Vec2 boid_direction(int j, const Agent& b) const;
};

}  // namespace animrt::herd
