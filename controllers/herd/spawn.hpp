#pragma once
// Inside the herd: where a group's figures start.

#include <functional>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

// Figures start this many times the sum of their radii apart: closer, a
// flock's first steps push neighbours into each other.
inline constexpr double kSpawnSpacing = 1.6;

// `count` positions in `area` for figures of `radius`, each apart from the
// others and from every figure in `placed` by kSpawnSpacing times the sum of
// radii, and where `clear` holds (walls, the mesh). Sampled at random first;
// when sampling gives up (it cannot find the last gaps of a crowded area), the
// whole group is placed again by a deterministic scan of a fine grid over the
// area, which packs far closer. Empty when neither finds room.
std::optional<std::vector<Vec2>> spawn_positions(const Rect& area, int count, double radius,
                                                 std::span<const Agent> placed,
                                                 const std::function<bool(Vec2)>& clear,
                                                 std::mt19937_64& rng);

}  // namespace animrt::herd
