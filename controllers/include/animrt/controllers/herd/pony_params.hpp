#pragma once
// Parameter sets for pony-size walking figures (radius 0.25 m, 0.05-0.12
// m/s, turning at most 0.6 rad/s), stepped at dt = 0.1 s; docs/herd.md
// lists the same numbers for the scenes. The flock tests and benchmarks
// start from them.

#include "animrt/controllers/herd/reynolds_flock.hpp"
#include "animrt/controllers/herd/unity_flock.hpp"
#include "animrt/controllers/herd/wander_leader.hpp"

namespace animrt::herd {

inline WanderParams pony_leader(Vec2 center) {
  WanderParams w;
  w.speed = 0.08;
  w.turn_gain = 1.0;
  w.max_turn = 0.2;
  w.wander_m = rect_around(center, {10.0, 10.0});
  w.reach_m = 1.0;
  return w;
}

inline ReynoldsFlockParams pony_reynolds() {
  ReynoldsFlockParams p;
  p.min_velocity = 0.0;
  p.max_velocity = 0.12;
  p.flock_size = 30;
  p.center_weight = 0.05;
  p.velocity_weight = 1.0;
  p.separation_weight = 1.0;
  p.follow_weight = 0.3;
  p.randomize_weight = 0.05;
  p.separation_radius = 2.0;
  return p;
}

inline UnityFlockParams pony_unity() {
  UnityFlockParams p;
  p.min_speed = 0.0;
  p.turn_speed = 0.6;
  p.random_freq = 1.0;
  p.random_force = 0.01;
  p.to_origin_force = 0.05;
  p.to_origin_range = 1.0;
  p.gravity = 0.02;
  p.avoidance_radius = 1.0;
  p.avoidance_force = 30.0;
  p.follow_velocity = 0.1;
  p.follow_radius = 2.0;
  p.max_length_delta = 100.0;
  return p;
}

}  // namespace animrt::herd
