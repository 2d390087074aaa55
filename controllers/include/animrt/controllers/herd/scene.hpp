#pragma once
// The herd's scene file (docs/herd.md): the ground, its walls and moving
// obstacles, the kinds of walking figure, and the groups that walk on it.
// Loading checks every key and value; the geometric checks that need the
// navigation mesh (spawn areas inside walls, targets without a path) are
// done when the herd is built (make_herd), at the same locations.

#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"
#include "animrt/controllers/herd/nav_world.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt::herd {

struct FigureSpec {
  std::string name;
  std::string robot;  // robot file (its gait is the figure's gait), or ""
  std::string gait;   // gait file, when no robot file is given, or ""
  double radius_m = 0.25;
  Location where;
};

enum class GroupKind { crowd, unity, reynolds };

struct LeaderSpec {
  Rect wander_m;  // the leader picks its points inside this rectangle
  double speed_mps = 0.1;
  double reach_m = 1.0;    // a point this close counts as reached
  double turn_gain = 1.0;  // 1/s: how fast it turns toward its point (per second, of the angle)
  double max_turn_rad_s = 1e9;
  Location where;
};

struct GroupSpec {
  std::string name;
  GroupKind kind = GroupKind::crowd;
  std::string figure;  // a FigureSpec name
  int count = 1;
  Rect spawn_m;
  std::optional<Vec2> target_m;                        // crowds
  std::optional<std::pair<double, double>> speed_mps;  // crowds: random speed range
  std::optional<LeaderSpec> leader;                    // flocks
  std::optional<YamlNode> params;                      // the kind's parameters, read by make_herd
  Location where;
  Location spawn_where, target_where;
};

struct HerdScene {
  std::string file;
  std::string name;
  std::uint64_t seed = 1;
  Rect bounds_m;
  std::vector<Box> walls;
  std::vector<Location> wall_where;
  std::vector<MovingObstacle> moving_obstacles;
  std::vector<Location> obstacle_where;
  std::string geometry_obj;  // extra static geometry (OBJ), "" for none
  std::vector<FigureSpec> figures;
  std::vector<GroupSpec> groups;
  double step_s = 0.1;      // herd step
  double output_hz = 10.0;  // CSV rows per agent per second
  double duration_s = 300.0;

  const FigureSpec* find_figure(const std::string& figure_name) const;
  int agent_count() const;
};

// Throws InputError naming the file, line, column and key.
HerdScene load_herd_scene(const std::string& path);
HerdScene parse_herd_scene(const YamlNode& root);

}  // namespace animrt::herd
