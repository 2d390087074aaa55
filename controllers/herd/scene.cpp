#include "animrt/controllers/herd/scene.hpp"

#include <climits>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <set>

#include "animrt/core/error.hpp"

namespace animrt::herd {
namespace {

// Plausible scene sizes (docs/herd.md lists them). A herd walks a paddock,
// a show floor or a plaza: 200 m a side is wider than a football pitch, and
// the navigation mesh (10 cm cells) of a larger ground would take minutes
// and gigabytes to build. Coordinates may sit anywhere within 1 km of the
// origin.
constexpr double kMaxCoordinateM = 1000.0;
constexpr double kMaxSideM = 200.0;

std::vector<double> numbers(const YamlNode& node, std::size_t n) {
  if (!node.is_sequence()) {
    node.fail("expected a list of " + std::to_string(n) + " numbers, found " + node.describe());
  }
  const auto items = node.items();
  if (items.size() != n) {
    node.fail("expected " + std::to_string(n) + " numbers, found " + std::to_string(items.size()));
  }
  std::vector<double> out;
  for (const YamlNode& item : items) {
    out.push_back(item.as_double());
  }
  return out;
}

// Numbers that are positions in the scene, metres.
std::vector<double> coordinates(const YamlNode& node, std::size_t n) {
  const auto v = numbers(node, n);
  const auto items = node.items();
  for (std::size_t i = 0; i < n; ++i) {
    if (std::abs(v[i]) > kMaxCoordinateM) {
      items[i].fail("expected a coordinate from -" + format_number(kMaxCoordinateM) + " to " +
                    format_number(kMaxCoordinateM) + " m, found " + items[i].describe());
    }
  }
  return v;
}

Vec2 point(const YamlNode& node) {
  const auto v = coordinates(node, 2);
  return {v[0], v[1]};
}

Rect rect(const YamlNode& node) {
  const auto v = coordinates(node, 4);
  if (!(v[0] < v[2]) || !(v[1] < v[3])) {
    node.fail("expected [xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax, found " +
              node.describe());
  }
  if (v[2] - v[0] > kMaxSideM || v[3] - v[1] > kMaxSideM) {
    node.fail("expected an area at most " + format_number(kMaxSideM) + " m a side, found " +
              format_number(v[2] - v[0]) + " x " + format_number(v[3] - v[1]) + " m");
  }
  return {v[0], v[1], v[2], v[3]};
}

Vec2 positive_size(const YamlNode& node) {
  const auto v = numbers(node, 2);
  const Vec2 s{v[0], v[1]};
  if (!(s.x > 0) || !(s.y > 0)) node.fail("expected two sizes > 0, found " + node.describe());
  if (s.x > kMaxSideM || s.y > kMaxSideM) {
    node.fail("expected sizes up to " + format_number(kMaxSideM) + " m, found " + node.describe());
  }
  return s;
}

Box box(const YamlNode& node) {
  Box b;
  b.center = point(node.at("center_m"));
  b.size = positive_size(node.at("size_m"));
  if (auto y = node.find("yaw_deg"))
    b.yaw_rad = y->as_double_in(-360, 360) * std::numbers::pi / 180;
  return b;
}

// Whether any of the box lies on the ground: one wholly outside it does
// nothing there, and is a typo (a wall at x = 1000 in a 40 m scene).
bool overlaps(const Rect& ground, const Box& b) {
  const double c = std::abs(std::cos(b.yaw_rad)), s = std::abs(std::sin(b.yaw_rad));
  const double hx = 0.5 * (c * b.size.x + s * b.size.y);
  const double hy = 0.5 * (s * b.size.x + c * b.size.y);
  return b.center.x + hx > ground.xmin && b.center.x - hx < ground.xmax &&
         b.center.y + hy > ground.ymin && b.center.y - hy < ground.ymax;
}

bool inside(const Rect& outer, const Rect& inner) {
  return inner.xmin >= outer.xmin && inner.xmax <= outer.xmax && inner.ymin >= outer.ymin &&
         inner.ymax <= outer.ymax;
}

std::string resolve(const std::filesystem::path& folder, const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

GroupKind kind_of(const YamlNode& node) {
  const std::string k = node.as_string();
  if (k == "crowd") return GroupKind::crowd;
  if (k == "unity") return GroupKind::unity;
  if (k == "reynolds") return GroupKind::reynolds;
  node.fail("expected crowd, unity or reynolds, found " + node.describe());
}

LeaderSpec leader(const YamlNode& node, const Rect& bounds) {
  node.allow_only({"wander_m", "speed_mps", "reach_m", "turn_gain", "max_turn_dps"});
  LeaderSpec l;
  l.where = node.location();
  const YamlNode w = node.at("wander_m");
  l.wander_m = rect(w);
  if (!inside(bounds, l.wander_m)) w.fail("the wander area must lie inside bounds_m");
  if (auto s = node.find("speed_mps")) l.speed_mps = s->as_double_in(0.001, 10.0);
  if (auto r = node.find("reach_m")) l.reach_m = r->as_double_in(0.01, 100.0);
  if (auto g = node.find("turn_gain")) l.turn_gain = g->as_double_in(0.001, 100.0);
  if (auto m = node.find("max_turn_dps"))
    l.max_turn_rad_s = m->as_double_in(0.01, 36000.0) * std::numbers::pi / 180;
  return l;
}

GroupSpec group(const YamlNode& node, const HerdScene& scene, std::set<std::string>& names) {
  GroupSpec g;
  g.where = node.location();
  const YamlNode kind = node.at("kind");
  g.kind = kind_of(kind);
  if (g.kind == GroupKind::crowd) {
    node.allow_only(
        {"name", "kind", "figure", "count", "spawn_m", "target_m", "speed_mps", "params"});
  } else {
    node.allow_only({"name", "kind", "figure", "count", "spawn_m", "leader", "params"});
  }
  const YamlNode name = node.at("name");
  g.name = name.as_string();
  if (g.name.empty()) name.fail("expected a non-empty name");
  if (!names.insert(g.name).second)
    name.fail("a group named '" + elide(g.name) + "' is already defined");
  const YamlNode figure = node.at("figure");
  g.figure = figure.as_string();
  if (scene.find_figure(g.figure) == nullptr) {
    figure.fail("no figure named '" + elide(g.figure) + "' in figures");
  }
  g.count = static_cast<int>(node.at("count").as_int_in(1, 100000));
  const YamlNode spawn = node.at("spawn_m");
  g.spawn_m = rect(spawn);
  g.spawn_where = spawn.location();
  if (!inside(scene.bounds_m, g.spawn_m)) spawn.fail("the spawn area must lie inside bounds_m");
  if (g.kind == GroupKind::crowd) {
    const YamlNode target = node.at("target_m");
    g.target_m = point(target);
    g.target_where = target.location();
    if (!scene.bounds_m.contains(*g.target_m)) target.fail("the target must lie inside bounds_m");
    const YamlNode speed = node.at("speed_mps");
    const auto v = numbers(speed, 2);
    if (!(v[0] > 0) || !(v[0] <= v[1]) || v[1] > 10) {
      speed.fail("expected [min, max] with 0 < min <= max <= 10, found " + speed.describe());
    }
    g.speed_mps = std::pair{v[0], v[1]};
  } else {
    g.leader = leader(node.at("leader"), scene.bounds_m);
  }
  if (auto p = node.find("params")) {
    if (!p->is_map()) p->fail("expected a map of parameters, found " + p->describe());
    g.params = *p;
  }
  return g;
}

}  // namespace

const FigureSpec* HerdScene::find_figure(const std::string& figure_name) const {
  for (const FigureSpec& f : figures) {
    if (f.name == figure_name) return &f;
  }
  return nullptr;
}

int HerdScene::agent_count() const {
  int n = 0;
  for (const GroupSpec& g : groups) n += g.count;
  return n;
}

HerdScene parse_herd_scene(const YamlNode& root) {
  root.allow_only({"name", "seed", "bounds_m", "walls", "moving_obstacles", "geometry_obj",
                   "figures", "groups", "step_s", "output_hz", "duration_s"});
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(root.file()).parent_path();
  HerdScene scene;
  scene.file = root.file();
  scene.name = root.get_string("name", "");
  if (auto s = root.find("seed"))
    scene.seed = static_cast<std::uint64_t>(s->as_int_in(0, INT64_MAX));
  scene.bounds_m = rect(root.at("bounds_m"));
  if (auto s = root.find("step_s")) scene.step_s = s->as_double_in(0.001, 1.0);
  if (auto s = root.find("output_hz")) scene.output_hz = s->as_double_in(0.01, 1000.0);
  if (auto s = root.find("duration_s")) scene.duration_s = s->as_double_in(0.001, 1e6);

  if (auto walls = root.find("walls")) {
    for (const YamlNode& w : walls->items()) {
      w.allow_only({"center_m", "size_m", "yaw_deg"});
      scene.walls.push_back(box(w));
      if (!overlaps(scene.bounds_m, scene.walls.back())) {
        w.at("center_m").fail("the wall lies wholly outside bounds_m");
      }
      scene.wall_where.push_back(w.location());
    }
  }
  if (auto obstacles = root.find("moving_obstacles")) {
    for (const YamlNode& o : obstacles->items()) {
      o.allow_only({"center_m", "size_m", "yaw_deg", "period_s", "down_fraction", "phase_s"});
      MovingObstacle m;
      scene.obstacle_where.push_back(o.location());
      m.footprint = box(o);
      if (!overlaps(scene.bounds_m, m.footprint)) {
        o.at("center_m").fail("the obstacle lies wholly outside bounds_m");
      }
      if (auto p = o.find("period_s")) m.period_s = p->as_double_in(0.1, 1e6);
      if (auto d = o.find("down_fraction")) m.down_fraction = d->as_double_in(0.0, 1.0);
      if (auto p = o.find("phase_s")) m.phase_s = p->as_double_in(0.0, 1e6);
      scene.moving_obstacles.push_back(m);
    }
  }
  if (auto g = root.find("geometry_obj")) {
    scene.geometry_obj = resolve(folder, g->as_string());
    if (!fs::is_regular_file(scene.geometry_obj)) g->fail("no such file: " + scene.geometry_obj);
  }

  const YamlNode figures = root.at("figures");
  const auto figure_entries = figures.entries();
  if (figure_entries.empty()) figures.fail("expected at least one figure, found an empty map");
  for (const auto& [name, node] : figure_entries) {
    node.allow_only({"robot", "gait", "radius_m"});
    FigureSpec f;
    f.name = name;
    f.where = node.location();
    const auto robot = node.find("robot");
    const auto gait = node.find("gait");
    if (robot.has_value() == gait.has_value()) node.fail("expected exactly one of robot and gait");
    const YamlNode& file = robot ? *robot : *gait;
    (robot ? f.robot : f.gait) = resolve(folder, file.as_string());
    const std::string& path = robot ? f.robot : f.gait;
    if (!fs::is_regular_file(path)) file.fail("no such file: " + path);
    if (auto r = node.find("radius_m")) f.radius_m = r->as_double_in(0.01, 10.0);
    scene.figures.push_back(f);
  }

  const YamlNode groups = root.at("groups");
  const auto group_items = groups.items();
  if (group_items.empty()) groups.fail("expected at least one group, found an empty list");
  std::set<std::string> names;
  for (const YamlNode& g : group_items) scene.groups.push_back(group(g, scene, names));
  return scene;
}

HerdScene load_herd_scene(const std::string& path) {
  return parse_herd_scene(YamlNode::load_file(path));
}

}  // namespace animrt::herd
