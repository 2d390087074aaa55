#pragma once
// Inside the herd: building the navigation mesh and the groups of a scene.

#include <memory>
#include <random>
#include <span>
#include <vector>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt::herd {

// Whether a figure of `radius` at p overlaps `box`.
bool overlaps_box(const Box& box, Vec2 p, double radius);

// The scene's navigation mesh (ground, walls, OBJ geometry, moving
// obstacles), or null when no group needs one and nothing moves.
std::unique_ptr<NavWorld> make_nav_world(const HerdScene& scene, double max_radius);

// One group per scene group, over `members` (agent indices per group); the
// crowd every crowd group shares is made in `crowd` (it must outlive them).
// Throws InputError at the scene's locations (unknown parameters, a target
// with no path from the spawn area).
std::vector<std::unique_ptr<HerdGroup>> make_groups(const HerdScene& scene,
                                                    const std::vector<std::vector<int>>& members,
                                                    std::span<const Agent> agents,
                                                    const std::vector<Figure>& figures,
                                                    const std::vector<int>& figure_of,
                                                    NavWorld* nav, std::unique_ptr<Crowd>& crowd);

}  // namespace animrt::herd
