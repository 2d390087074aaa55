#pragma once
// Pieces both flocking variants share: how a boid reads its own motion off
// the walking figure, random draws on the plane, Unity's RotateTowards on
// the plane, and the checks on a group's member list.

#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

// How a flock finds neighbours: the grid, or every agent (the reference the
// grid is measured and tested against).
enum class NeighbourSearch { grid, all_pairs };

// The direction an agent moves in: its walked velocity's, or its heading
// when it stands still.
inline Vec2 motion_direction(const Agent& a) {
  return a.speed != 0.0 ? normalized(a.velocity()) : heading_vector(a.heading);
}

// A uniform point in the unit disc (rejection from the square).
Vec2 random_in_unit_disc(std::mt19937_64& rng);
// A uniform direction.
Vec2 random_unit_vector(std::mt19937_64& rng);

// Turns `current` toward `target` by at most max_radians and moves its
// length toward target's by at most max_length_delta. When either is the
// zero vector it moves straight toward target by at most max_length_delta
// (as Unity's Vector3.RotateTowards does).
Vec2 rotate_towards(Vec2 current, Vec2 target, double max_radians, double max_length_delta);

// Throws std::invalid_argument unless every index is >= 0 and none repeats.
void check_members(std::span<const int> members, const char* who);

// max index + 1 (0 for no members).
std::size_t herd_size_needed(std::span<const int> members);

}  // namespace animrt::herd
