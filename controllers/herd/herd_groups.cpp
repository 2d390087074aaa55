// Building a scene's navigation mesh and groups, with each kind's
// parameters read from the group's `params` map.

#include "herd_groups.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "animrt/controllers/herd/crowd.hpp"
#include "animrt/controllers/herd/nav_world.hpp"
#include "animrt/controllers/herd/reynolds_flock.hpp"
#include "animrt/controllers/herd/unity_flock.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/core/error.hpp"

namespace animrt::herd {
namespace {

// How far from the walkable ground a target may lie: as far as a path
// search snaps its ends (NavWorld::has_path).
constexpr double kTargetSnapM = 0.3;

// One parameter of a kind: its key, where it goes, its range.
struct Param {
  const char* key;
  double* value;
  double lo, hi;
};

// Reads every key of `params` into the table; an unknown key, a wrong type
// or a value out of range is an InputError at the key.
void read_params(const std::optional<YamlNode>& params, std::span<const Param> table) {
  if (!params) return;
  std::vector<std::string_view> keys;
  for (const Param& p : table) keys.push_back(p.key);
  params->allow_only(keys);
  for (const Param& p : table) {
    if (auto node = params->find(p.key)) *p.value = node->as_double_in(p.lo, p.hi);
  }
}

WanderLeader make_leader(const GroupSpec& spec, std::uint64_t seed) {
  const LeaderSpec& l = *spec.leader;
  WanderParams w;
  w.speed = l.speed_mps;
  w.turn_gain = l.turn_gain;
  w.max_turn = l.max_turn_rad_s;
  w.wander_m = l.wander_m;
  w.reach_m = l.reach_m;
  const Vec2 start = spec.spawn_m.center();
  const Vec2 aim = l.wander_m.center() - start;
  const double heading = norm(aim) > 1e-9 ? std::atan2(aim.y, aim.x) : 0.0;
  return WanderLeader(w, start, heading, seed);
}

std::uint64_t group_seed(std::uint64_t scene_seed, std::size_t g) {
  // Distinct, reproducible streams per group (splitmix64 of seed and index).
  std::uint64_t z = scene_seed + 0x9E3779B97F4A7C15ull * (g + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

class FlockGroup final : public HerdGroup {
 public:
  explicit FlockGroup(std::unique_ptr<GroupSteering> flock, std::function<Vec2()> leader)
      : flock_(std::move(flock)), leader_(std::move(leader)) {}
  GroupSteering& steering() override { return *flock_; }
  std::optional<Vec2> leader() const override { return leader_(); }

 private:
  std::unique_ptr<GroupSteering> flock_;
  std::function<Vec2()> leader_;
};

class CrowdTeam final : public HerdGroup {
 public:
  explicit CrowdTeam(std::unique_ptr<CrowdGroup> group) : group_(std::move(group)) {
    const auto members = group_->members();
    for (std::size_t k = 0; k < members.size(); ++k) index_[members[k]] = k;
  }
  GroupSteering& steering() override { return *group_; }
  bool arrived(int agent) const override { return group_->arrived(index_.at(agent)); }
  double max_speed(int agent) const override { return group_->max_speed(index_.at(agent)); }

 private:
  std::unique_ptr<CrowdGroup> group_;
  std::map<int, std::size_t> index_;
};

}  // namespace

std::unique_ptr<NavWorld> make_nav_world(const HerdScene& scene, double max_radius) {
  const bool crowds = std::any_of(scene.groups.begin(), scene.groups.end(),
                                  [](const GroupSpec& g) { return g.kind == GroupKind::crowd; });
  if (!crowds && scene.moving_obstacles.empty()) return nullptr;
  NavWorldConfig config;
  config.bounds = scene.bounds_m;
  config.walls = scene.walls;
  config.moving = scene.moving_obstacles;
  config.agent_radius_m = max_radius;
  if (!scene.geometry_obj.empty()) {
    // OBJ files are y-up or z-up by habit; the scene's geometry is z-up, as the herd.
    const seqnet::MeshSequence mesh = seqnet::read_obj(scene.geometry_obj);
    for (const auto& tri : mesh.triangles) {
      for (int v : tri) {
        const auto p = mesh.frames.front().col(v);
        config.triangles.push_back({p.x(), p.y(), p.z()});
      }
    }
  }
  return std::make_unique<NavWorld>(std::move(config));
}

std::vector<std::unique_ptr<HerdGroup>> make_groups(const HerdScene& scene,
                                                    const std::vector<std::vector<int>>& members,
                                                    std::span<const Agent> agents,
                                                    const std::vector<Figure>& figures,
                                                    const std::vector<int>& figure_of,
                                                    NavWorld* nav, std::unique_ptr<Crowd>& crowd) {
  std::vector<std::unique_ptr<HerdGroup>> groups;
  CrowdParams crowd_params;
  double crowd_turn = 1e9;
  for (std::size_t g = 0; g < scene.groups.size(); ++g) {
    const GroupSpec& spec = scene.groups[g];
    if (spec.kind != GroupKind::crowd) continue;
    const Figure& f =
        figures[static_cast<std::size_t>(figure_of[static_cast<std::size_t>(members[g].front())])];
    crowd_turn = std::min(crowd_turn, f.walk.max_turn(spec.speed_mps->second));
    crowd_params.figure_start_speed_m_s =
        std::max(crowd_params.figure_start_speed_m_s, f.walk.min_speed());
  }
  crowd_params.step_s = scene.step_s;
  crowd_params.unstick_after_s = 5.0;  // the herd keeps figures out of walls (Herd::step)
  for (std::size_t g = 0; g < scene.groups.size(); ++g) {
    const GroupSpec& spec = scene.groups[g];
    const std::uint64_t seed = group_seed(scene.seed, g);
    const std::string where = "groups[" + std::to_string(g) + "].params";
    if (spec.kind == GroupKind::unity) {
      UnityFlockParams p;
      const Param table[] = {{"min_speed", &p.min_speed, 0, 100},
                             {"turn_speed", &p.turn_speed, 0, 1000},
                             {"random_freq", &p.random_freq, 1e-6, 1000},
                             {"random_force", &p.random_force, 0, 1e4},
                             {"to_origin_force", &p.to_origin_force, 0, 1e4},
                             {"to_origin_range", &p.to_origin_range, 1e-6, 1e6},
                             {"gravity", &p.gravity, 0, 1e4},
                             {"avoidance_radius", &p.avoidance_radius, 1e-6, 1e6},
                             {"avoidance_force", &p.avoidance_force, 0, 1e4},
                             {"follow_velocity", &p.follow_velocity, 0, 1e4},
                             {"follow_radius", &p.follow_radius, 1e-6, 1e6},
                             {"max_length_delta", &p.max_length_delta, 0, 1e6}};
      read_params(spec.params, table);
      validate(p);
      auto flock =
          std::make_unique<UnityFlock>(members[g], p, make_leader(spec, seed), seed, agents.size());
      const UnityFlock* view = flock.get();
      groups.push_back(std::make_unique<FlockGroup>(std::move(flock),
                                                    [view] { return view->leader().position(); }));
    } else if (spec.kind == GroupKind::reynolds) {
      ReynoldsFlockParams p;
      double flock_size = spec.count;
      const Param table[] = {{"min_velocity", &p.min_velocity, 0, 100},
                             {"max_velocity", &p.max_velocity, 1e-6, 100},
                             {"flock_size", &flock_size, 1, 100000},
                             {"center_weight", &p.center_weight, 0, 1e4},
                             {"velocity_weight", &p.velocity_weight, 0, 1e4},
                             {"separation_weight", &p.separation_weight, 0, 1e4},
                             {"follow_weight", &p.follow_weight, 0, 1e4},
                             {"randomize_weight", &p.randomize_weight, 0, 1e4},
                             {"separation_radius", &p.separation_radius, 1e-6, 1e6}};
      read_params(spec.params, table);
      if (static_cast<int>(flock_size) != spec.count) {
        throw InputError(
            spec.params->at("flock_size").location(), where + ".flock_size",
            "the flock size is the group's count (" + std::to_string(spec.count) + ")");
      }
      if (p.min_velocity > p.max_velocity) {
        throw InputError(spec.where, where, "min_velocity must not exceed max_velocity");
      }
      p.flock_size = spec.count;
      validate(p);
      auto flock = std::make_unique<ReynoldsFlock>(members[g], p, make_leader(spec, seed), seed,
                                                   agents.size());
      const ReynoldsFlock* view = flock.get();
      groups.push_back(std::make_unique<FlockGroup>(std::move(flock),
                                                    [view] { return view->leader().position(); }));
    } else {
      if (!crowd) {
        crowd_params.figure_turn_rad_s = crowd_turn;
        crowd = std::make_unique<Crowd>(*nav, agents, crowd_params);
      }
      CrowdGroupParams p;
      p.target = *spec.target_m;
      p.speed_min_mps = spec.speed_mps->first;
      p.speed_max_mps = spec.speed_mps->second;
      p.seed = seed;
      const Param table[] = {{"slot_spacing_m", &p.slot_spacing_m, 0, 100},
                             {"assign_distance_m", &p.assign_distance_m, 0, 1e4},
                             {"arrive_tolerance_m", &p.arrive_tolerance_m, 0.001, 100}};
      read_params(spec.params, table);
      const Figure& f = figures[static_cast<std::size_t>(
          figure_of[static_cast<std::size_t>(members[g].front())])];
      if (p.speed_max_mps > f.walk.max_speed() * (1 + 1e-9)) {
        throw InputError(spec.where, "groups[" + std::to_string(g) + "].speed_mps",
                         "figure '" + elide(f.name) + "' walks at most " +
                             format_number(f.walk.max_speed()) +
                             " m/s (its gait's steering range)");
      }
      // A target off the walkable ground (in a wall, or nearer a wall or
      // the ground's edge than a figure's centre comes) is no place to
      // walk to, whatever the spawn area.
      if (!nav->nearest_on_mesh(p.target, kTargetSnapM)) {
        const std::string place = nav->in_wall(p.target, 0.0)
                                      ? "inside a wall"
                                      : "off the walkable ground (too near a wall or the "
                                        "ground's edge for a figure's centre)";
        const auto nearest = nav->nearest_on_mesh(p.target, 1e3);
        throw InputError(
            spec.target_where, "groups[" + std::to_string(g) + "].target_m",
            "the target is " + place +
                (nearest ? "; the nearest walkable point is [" + format_number(nearest->x + 0.0) +
                               ", " + format_number(nearest->y + 0.0) + "]"
                         : std::string()));
      }
      for (int i : members[g]) {
        if (!nav->has_path(agents[static_cast<std::size_t>(i)].position, p.target)) {
          throw InputError(spec.target_where, "groups[" + std::to_string(g) + "].target_m",
                           "no path from the spawn area to the target (agent " + spec.name + "." +
                               std::to_string(i - members[g].front()) + ")");
        }
      }
      groups.push_back(
          std::make_unique<CrowdTeam>(std::make_unique<CrowdGroup>(*crowd, agents, members[g], p)));
    }
  }
  return groups;
}

}  // namespace animrt::herd
