#pragma once
// The point a flock follows: it walks forward at a constant speed, turns its
// heading toward its next goal by a fixed fraction of the angle per second,
// and draws a new goal uniformly inside a rectangle whenever it comes within
// reach of the current one. It is not a figure, only a moving target.

#include <cstdint>
#include <limits>
#include <random>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

struct WanderParams {
  double speed = 100.0;    // m/s (the text's default, for birds)
  double turn_gain = 1.0;  // 1/s: per step the heading turns by min(1, gain*dt) of the angle
  double max_turn = std::numeric_limits<double>::infinity();  // rad/s, cap on that turn
  Rect wander_m{-50.0, -50.0, 50.0, 50.0};  // m, where goals are drawn (world frame)
  double reach_m = 10.0;                    // m, a goal this close counts as reached
};

// The rectangle of half-size `half` around `center` (the text's bound
// around the start position).
inline Rect rect_around(Vec2 center, Vec2 half) {
  return {center.x - half.x, center.y - half.y, center.x + half.x, center.y + half.y};
}

// A uniform double in [0, 1) from 53 random bits (the same numbers on every
// standard library, unlike std::uniform_real_distribution).
inline double unit_uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

class WanderLeader {
 public:
  // Throws std::invalid_argument for a negative speed, gain or reach, or an
  // empty or non-finite rectangle.
  WanderLeader(const WanderParams& params, Vec2 start, double heading, std::uint64_t seed);

  // Moves forward by speed*dt on the current heading, then turns toward the
  // goal, then draws a new goal if within reach.
  void step(double dt);

  Vec2 position() const { return pos_; }
  double heading() const { return heading_; }
  Vec2 velocity() const { return heading_vector(heading_) * params_.speed; }
  Vec2 goal() const { return goal_; }
  const WanderParams& params() const { return params_; }
  int goals_drawn() const { return goals_drawn_; }

 private:
  void next_goal();

  WanderParams params_;
  Vec2 pos_;
  double heading_;
  Vec2 goal_;
  std::mt19937_64 rng_;
  int goals_drawn_ = 0;
};

// The angle a - b wrapped to (-pi, pi].
double angle_diff(double a, double b);

}  // namespace animrt::herd
