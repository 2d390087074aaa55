#pragma once
// The walkable world of a crowd: a tiled navigation mesh (Recast/Detour,
// through a tile cache so obstacles can carve it at run time) built from the
// ground rectangle, static walls and optional triangle geometry, plus
// obstacles that drop onto the ground and rise again on a schedule.
//
// Herd coordinates are x-y on the ground (z up); Recast is y-up. The mapping
// is herd (x, y, z) -> Recast (x, z, -y), a proper rotation, so triangle
// winding and yaw angles carry over unchanged (a box's herd yaw is its
// Recast yaw).

#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

class dtNavMesh;
class dtNavMeshQuery;
class dtTileCache;
class dtQueryFilter;

namespace animrt::herd {

// A wall that is down (carving the mesh, blocking the way) for the first
// down_fraction of every period and up (out of the way) for the rest; the
// schedule is shifted by phase_s: down while fmod(t - phase_s, period_s) <
// down_fraction * period_s.
struct MovingObstacle {
  Box footprint;
  double period_s = 8.0;
  double down_fraction = 0.5;
  double phase_s = 0.0;
  // Time into the current period at time t; the wall is down for the
  // first down_fraction of each period.
  double time_in_period(double t) const {
    const double u = t - phase_s;
    return u - std::floor(u / period_s) * period_s;
  }
};

struct NavWorldConfig {
  Rect bounds;             // the ground, walkable at z = 0
  std::vector<Box> walls;  // static, extruded wall_height_m high
  // Extra geometry as a triangle soup: every three points are one triangle,
  // herd coordinates (z up), counter-clockwise seen from above for a floor.
  std::vector<std::array<double, 3>> triangles;
  std::vector<MovingObstacle> moving;
  double agent_radius_m = 0.25;  // the largest figure's radius: the mesh keeps this far from walls
  double agent_height_m = 1.5;   // clearance a figure needs (more than the walls' height)
  double agent_climb_m = 0.2;    // step a figure can climb
  double cell_size_m = 0.1;
  double cell_height_m = 0.05;
  double wall_height_m = 1.0;
  int tile_cells = 64;  // tile edge in cells
  int max_obstacles = 64;
};

class NavWorld {
 public:
  // Builds the mesh; throws std::runtime_error when Recast or Detour fails
  // (out of memory, a world too large for the tile budget).
  explicit NavWorld(NavWorldConfig config);
  ~NavWorld();
  NavWorld(const NavWorld&) = delete;
  NavWorld& operator=(const NavWorld&) = delete;

  const NavWorldConfig& config() const { return config_; }

  // Applies the moving obstacles' schedule at time t and rebuilds the
  // carved tiles until the mesh is up to date. A drop is deferred while any
  // agent stands within its footprint grown by the agent radius (it would be
  // trapped); it happens at the first update when they have moved off.
  // Calling it again with the same t changes nothing.
  void update(double t, std::span<const Agent> agents);

  // Whether obstacle i currently carves the mesh.
  bool obstacle_down(std::size_t i) const { return obstacles_[i].down; }
  // Down windows in which an obstacle had to wait for agents to move off
  // (each window counts once).
  int deferred_drops() const { return deferred_drops_; }
  // Drops that happened (each down window counts once).
  int drops() const { return drops_; }

  // Whether p is on the walkable mesh (within tol_m horizontally).
  bool on_mesh(Vec2 p, double tol_m = 0.02) const;
  // Whether a disc of the given radius at p overlaps a static wall or a
  // dropped obstacle.
  bool in_wall(Vec2 p, double radius_m) const;
  // Whether a complete path leads from `from` to `to` (both within
  // snap_m of the mesh).
  bool has_path(Vec2 from, Vec2 to, double snap_m = 0.3) const;
  // Length of the shortest path along the mesh, or nothing without a
  // complete path.
  std::optional<double> path_length(Vec2 from, Vec2 to, double snap_m = 0.3) const;
  // The shortest path's corners along the mesh, from the point on the mesh
  // nearest `from` to the one nearest `to`, or nothing without a complete
  // path.
  std::optional<std::vector<Vec2>> path(Vec2 from, Vec2 to, double snap_m = 0.3) const;
  static double straight_length(Vec2 from, Vec2 to) { return norm(to - from); }
  // The nearest point on the mesh within snap_m, or nothing.
  std::optional<Vec2> nearest_on_mesh(Vec2 p, double snap_m) const;

  dtNavMesh* navmesh() { return navmesh_; }
  dtNavMeshQuery* query() const { return query_; }
  const dtQueryFilter& filter() const;

  static std::array<float, 3> to_recast(Vec2 p, double z = 0.0) {
    return {static_cast<float>(p.x), static_cast<float>(z), static_cast<float>(-p.y)};
  }
  static Vec2 from_recast(const float* v) { return {v[0], -v[2]}; }

  // Distance from p to a box (0 inside it).
  static double distance_to_box(Vec2 p, const Box& b);

 private:
  struct ObstacleState {
    bool down = false;
    bool deferred_this_window = false;
    bool dropped_this_window = false;
    unsigned int ref = 0;
  };
  void build_tiles();
  void add_obstacle(std::size_t i);
  void flush();

  NavWorldConfig config_;
  struct Parts;  // the tile cache's allocator, compressor and mesh callback
  std::unique_ptr<Parts> parts_;
  dtTileCache* tile_cache_ = nullptr;
  dtNavMesh* navmesh_ = nullptr;
  dtNavMeshQuery* query_ = nullptr;
  std::vector<ObstacleState> obstacles_;
  int deferred_drops_ = 0;
  int drops_ = 0;
};

}  // namespace animrt::herd
