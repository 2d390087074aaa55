#pragma once
// What the flock tests share: the pony-size parameter sets, a leader that
// stays put, agents and member lists.

#include <vector>

#include "animrt/controllers/herd/pony_params.hpp"

namespace animrt::herd::test {

using herd::pony_leader;
using herd::pony_reynolds;
using herd::pony_unity;

// Shared by the flock tests: a leader that stays at `at`, an agent, and
// member lists 0..n-1.
inline WanderLeader still_leader(Vec2 at) {
  WanderParams w;
  w.speed = 0.0;
  w.wander_m = {at.x, at.y, at.x, at.y};
  w.reach_m = 0.0;
  return WanderLeader(w, at, 0.0, 1);
}

inline Agent agent(Vec2 p, double heading = 0.0, double speed = 0.0, int group = 0) {
  Agent a;
  a.position = p;
  a.heading = heading;
  a.speed = speed;
  a.group = group;
  return a;
}

inline std::vector<int> iota(int n) {
  std::vector<int> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = i;
  return v;
}

}  // namespace animrt::herd::test
