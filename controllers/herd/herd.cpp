#include "animrt/controllers/herd/herd.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "animrt/controllers/herd/crowd.hpp"
#include "animrt/controllers/herd/nav_world.hpp"
#include "herd_groups.hpp"
#include "spawn.hpp"

namespace animrt::herd {
namespace {

// Closest point of a box to p, and whether p is inside it.
Vec2 closest_on_box(const Box& box, Vec2 p, bool& inside) {
  const Vec2 ax = heading_vector(box.yaw_rad);
  const Vec2 ay{-ax.y, ax.x};
  const Vec2 d = p - box.center;
  const double u = dot(d, ax), v = dot(d, ay);
  const double hu = box.size.x / 2, hv = box.size.y / 2;
  inside = std::abs(u) <= hu && std::abs(v) <= hv;
  if (inside) {
    // Out through the nearest side.
    if (hu - std::abs(u) < hv - std::abs(v)) {
      return box.center + ax * std::copysign(hu, u) + ay * v;
    }
    return box.center + ax * u + ay * std::copysign(hv, v);
  }
  return box.center + ax * std::clamp(u, -hu, hu) + ay * std::clamp(v, -hv, hv);
}

// Which other groups' figures stand in `area` (or within spawn spacing of
// it), for the error when it has no room: "a (20 figures), b (3 figures)".
std::string occupants(const HerdScene& scene, std::span<const Agent> placed, const Rect& area,
                      double radius) {
  std::vector<int> count(scene.groups.size(), 0);
  for (const Agent& b : placed) {
    const double m = kSpawnSpacing * (radius + b.radius);
    const Rect near{area.xmin - m, area.ymin - m, area.xmax + m, area.ymax + m};
    if (near.contains(b.position)) ++count[static_cast<std::size_t>(b.group)];
  }
  std::string out;
  for (std::size_t g = 0; g < count.size(); ++g) {
    if (count[g] == 0) continue;
    if (!out.empty()) out += ", ";
    out += scene.groups[g].name + " (" + std::to_string(count[g]) + " figures)";
  }
  return out;
}

// A figure's walk from its gait file; the gait's error is told at the
// scene's figure (the file at fault may be named in several scenes).
WalkResponse walk_of(const FigureSpec& spec, const std::string& gait) {
  try {
    return load_walk_response(gait);
  } catch (const InputError& e) {
    // A robot file's own keys, met in a gait file: the figure names its
    // robot as a gait.
    const bool robot_file = spec.robot.empty() && (e.key() == "loop" || e.key() == "buses" ||
                                                   e.key() == "motion" || e.key() == "safety");
    throw InputError(
        spec.where, "figures." + spec.name + (spec.robot.empty() ? ".gait" : ".robot"),
        std::string(e.what()) + (robot_file ? " (a robot file? give it as robot:, its gait is the "
                                              "figure's)"
                                            : ""));
  }
}

// "" when the figure's gait turns; else the warning that it cannot. Its
// turns are read where its walk can go: every walking speed (sampled) and
// on the spot.
std::string cannot_turn(const FigureSpec& spec, const WalkResponse& walk) {
  constexpr double kLeastTurnRadS = 1.0 * M_PI / 180.0;  // under 1 deg/s: a drift's size
  constexpr int kSpeeds = 16;
  double best = walk.spot_turn();
  for (int k = 0; k <= kSpeeds; ++k) {
    const double v = walk.min_speed() + (walk.max_speed() - walk.min_speed()) * k / kSpeeds;
    best = std::max(best, walk.max_turn(v));
  }
  if (best >= kLeastTurnRadS) return "";
  char turn[32];
  std::snprintf(turn, sizeof turn, "%.2f", best * 180.0 / M_PI);
  const InputError said(spec.where, "figures." + spec.name,
                        std::string("its gait turns at most ") + turn +
                            " deg/s (no usable turning walk in its calibration, no turn on the "
                            "spot): it cannot steer toward a target nor mend its drift (animrt "
                            "gait calibrate, docs/gait.md)");
  return std::string("warning: ") + said.what();
}

}  // namespace

bool overlaps_box(const Box& box, Vec2 p, double radius) {
  bool inside = false;
  const Vec2 c = closest_on_box(box, p, inside);
  return inside || norm(p - c) < radius;
}

Herd::Herd(HerdScene scene, const GaitOfRobot& gait_of_robot, std::optional<std::uint64_t> seed)
    : scene_(std::move(scene)) {
  if (seed) scene_.seed = *seed;
  for (const FigureSpec& spec : scene_.figures) {
    const std::string gait = spec.gait.empty() ? gait_of_robot(spec.robot) : spec.gait;
    figures_.push_back(Figure{spec.name, spec.radius_m, walk_of(spec, gait)});
    turning_radius_.push_back(turning_radius(figures_.back()));
    const bool used = std::any_of(scene_.groups.begin(), scene_.groups.end(),
                                  [&](const GroupSpec& g) { return g.figure == spec.name; });
    if (const std::string w = used ? cannot_turn(spec, figures_.back().walk) : ""; !w.empty()) {
      warnings_.push_back(w);
    }
  }
  double max_radius = 0.0;
  for (const Figure& f : figures_) max_radius = std::max(max_radius, f.radius_m);
  nav_ = make_nav_world(scene_, max_radius);

  std::mt19937_64 rng(scene_.seed);
  std::vector<GroupInfo> infos;
  std::vector<std::vector<int>> members(scene_.groups.size());
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
    const GroupSpec& spec = scene_.groups[g];
    int figure = 0;
    while (figures_[static_cast<std::size_t>(figure)].name != spec.figure) ++figure;
    const double r = figures_[static_cast<std::size_t>(figure)].radius_m;
    const auto clear = [&](Vec2 p) {
      for (const Box& w : scene_.walls) {
        if (overlaps_box(w, p, r)) return false;
      }
      return !(nav_ && spec.kind == GroupKind::crowd) || nav_->on_mesh(p);
    };
    const auto positions = spawn_positions(spec.spawn_m, spec.count, r, agents_, clear, rng);
    if (!positions) {
      const std::string others = occupants(scene_, agents_, spec.spawn_m, r);
      throw InputError(
          spec.spawn_where, "groups." + spec.name + ".spawn_m",
          "the spawn area has no room for " + std::to_string(spec.count) + " figures of radius " +
              format_number(r) + " m clear of each other and of the walls" +
              (others.empty() ? std::string() : "; other groups' figures fill it: " + others));
    }
    for (int k = 0; k < spec.count; ++k) {
      Agent a;
      a.radius = r;
      a.group = static_cast<int>(g);
      a.position = (*positions)[static_cast<std::size_t>(k)];
      const Vec2 aim =
          spec.target_m ? *spec.target_m
                        : (spec.leader ? spec.leader->wander_m.center() : scene_.bounds_m.center());
      a.heading = std::atan2(aim.y - a.position.y, aim.x - a.position.x);
      members[g].push_back(static_cast<int>(agents_.size()));
      agents_.push_back(a);
      figure_of_.push_back(figure);
      names_.push_back(spec.name + "." + std::to_string(k));
    }
  }
  const std::size_t n = agents_.size();
  desired_.assign(n, Vec2{});
  commands_.assign(n, MotionCommand{});
  embodied_.assign(n, 0);
  leaders_scratch_.assign(scene_.groups.size(), std::nullopt);
  arrived_scratch_.assign(n, 0);
  max_speed_scratch_.assign(n, 0.0);
  groups_ = make_groups(scene_, members, agents_, figures_, figure_of_, nav_.get(), crowd_);
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) {
    const GroupSpec& spec = scene_.groups[g];
    infos.push_back(GroupInfo{spec.name,
                              spec.kind == GroupKind::crowd   ? "crowd"
                              : spec.kind == GroupKind::unity ? "unity"
                                                              : "reynolds",
                              members[g], spec.target_m});
  }
  // Flocks form in the first quarter of the run; order counts after it.
  recorder_ = std::make_unique<MetricsRecorder>(infos, agents_, scene_.duration_s / 4);
}

Herd::~Herd() = default;

int Herd::find_agent(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  return it == names_.end() ? -1 : static_cast<int>(it - names_.begin());
}

std::optional<Vec2> Herd::leader(int group) const {
  return groups_[static_cast<std::size_t>(group)]->leader();
}

bool Herd::arrived(int agent) const {
  const int g = agents_[static_cast<std::size_t>(agent)].group;
  return groups_[static_cast<std::size_t>(g)]->arrived(agent);
}

void Herd::keep_out_of_walls(Agent& agent) const {
  const auto push_out = [&](const Box& box) {
    bool inside = false;
    const Vec2 c = closest_on_box(box, agent.position, inside);
    const Vec2 away = inside ? c - agent.position : agent.position - c;
    const double d = norm(away);
    if (inside || d < agent.radius) {
      const Vec2 dir = d > 1e-12 ? away / d : heading_vector(agent.heading + M_PI);
      agent.position = c + dir * agent.radius;
    }
  };
  for (const Box& w : scene_.walls) push_out(w);
  if (nav_) {
    for (std::size_t k = 0; k < scene_.moving_obstacles.size(); ++k) {
      if (nav_->obstacle_down(k)) push_out(scene_.moving_obstacles[k].footprint);
    }
  }
  const Rect& b = scene_.bounds_m;
  agent.position.x = std::clamp(agent.position.x, b.xmin + agent.radius, b.xmax - agent.radius);
  agent.position.y = std::clamp(agent.position.y, b.ymin + agent.radius, b.ymax - agent.radius);
}

double Herd::turning_of(int agent) const {
  const Agent& a = agents_[static_cast<std::size_t>(agent)];
  if (scene_.groups[static_cast<std::size_t>(a.group)].kind != GroupKind::crowd) return -1.0;
  return turning_radius_[static_cast<std::size_t>(figure_of_[static_cast<std::size_t>(agent)])];
}

namespace {

// How much nearer a figure with `turning` radius, at `a`, comes to a point
// `to_other` away while it walks its tightest turn until it faces past it.
double turn_room(double turning, const Agent& a, Vec2 to_other) {
  const double dist = norm(to_other);
  if (turning <= 0.0 || dist <= 0.0) return 0.0;
  const double c = dot(heading_vector(a.heading), to_other) / dist;
  return c > 0.0 ? turning * (1.0 - std::sqrt(std::max(0.0, 1.0 - c * c))) : 0.0;
}

}  // namespace

void Herd::step() {
  const double dt = scene_.step_s;
  // The crowd moves the obstacles itself (before it plans); without one,
  // the herd does.
  if (nav_ && !crowd_) nav_->update(t_, agents_);
  for (auto& g : groups_) g->steering().steer(t_, dt, agents_, desired_);
  double reach = 0.0;  // farthest a figure can come toward another in one step
  for (std::size_t i = 0; i < agents_.size(); ++i) {
    const std::size_t f = static_cast<std::size_t>(figure_of_[i]);
    reach = std::max(reach, 2 * figures_[f].radius_m + 2 * figures_[f].walk.max_speed() * dt +
                                2 * turning_radius_[f]);
  }
  grid_.build(std::span<const Agent>(agents_), std::max(reach, 1e-3));
  for (std::size_t i = 0; i < agents_.size(); ++i) {
    const Figure& figure = figures_[static_cast<std::size_t>(figure_of_[i])];
    commands_[i] = steer_figure(figure, agents_[i], desired_[i], dt);
    if (embodied_[i]) continue;
    Agent next = agents_[i];
    walk_figure(figure, commands_[i], dt, next);
    // Flocks have no navigation mesh: a wall or a lowered obstacle stops a
    // figure at its surface (crowds steer around them before).
    keep_out_of_walls(next);
    // Figures are solid: the last guard, whatever the steering asked, is a
    // figure that stops rather than step into another. A crowd figure that
    // turns only while it walks stops short of that by the room it and the
    // one it faces need to walk their turns away: at contact every step of
    // such a turn closes on the other, and neither could ever leave.
    const double own_turning = turning_of(static_cast<int>(i));
    const bool crowd = own_turning >= 0.0;
    const double turning = std::max(own_turning, 0.0);
    bool blocked = false;
    Vec2 toward;  // unit vectors to the figures it would step into
    grid_.for_each_near(static_cast<int>(i), reach, [&](int j, double) {
      const Agent& other = agents_[static_cast<std::size_t>(j)];
      const double contact = next.radius + other.radius;
      const double other_turning = crowd ? std::max(turning_of(j), 0.0) : 0.0;
      const double near = contact + turning + other_turning;
      // Clear of contact by far more than rounding: no need of the exact
      // distances (most neighbours of the query are).
      if (norm2(next.position - other.position) > near * near * (1 + 1e-9)) return;
      const Vec2 from_before = other.position - agents_[i].position;
      const Vec2 from_after = other.position - next.position;
      const double before = norm(from_before);
      const double after = norm(from_after);
      // Walking the turn away at its fastest keeps the clearance as it is.
      // The other's room (if it must turn too) is taken as it was: a step
      // across its nose changes it, and would stop a figure turning clear.
      const double other_room = turn_room(other_turning, other, -from_before);
      const double clear_before =
          before - contact - turn_room(turning, agents_[i], from_before) - other_room;
      const double clear_after =
          after - contact - turn_room(turning, next, from_after) - other_room;
      if ((after < contact && after < before) ||
          (clear_after < 0.0 && clear_after < clear_before - 1e-6)) {
        blocked = true;
        if (before > 0.0) toward += from_before / before;
      }
    });
    if (blocked) {
      ++contact_stops_;
      // It stands; a flock's figure turns on the spot out of the way where
      // it can (in place: the drift of such a turn is ignored here). A
      // crowd plans around its neighbours and unsticks by its own rule.
      commands_[i] = crowd ? MotionCommand{} : turn_clear(figure, agents_[i], desired_[i], toward);
      const Vec2 at = agents_[i].position;
      walk_figure(figure, commands_[i], dt, agents_[i]);
      agents_[i].position = at;
      agents_[i].speed = 0.0;
      continue;
    }
    agents_[i] = next;
  }
  t_ += dt;
}

void Herd::embody(int agent) { embodied_[static_cast<std::size_t>(agent)] = 1; }

void Herd::set_pose(int agent, Vec2 position, double heading, double speed, double turn) {
  Agent& a = agents_[static_cast<std::size_t>(agent)];
  a.position = position;
  a.heading = heading;
  a.speed = speed;
  a.turn = turn;
}

void Herd::record_metrics() {
  for (std::size_t g = 0; g < scene_.groups.size(); ++g) leaders_scratch_[g] = groups_[g]->leader();
  for (std::size_t i = 0; i < agents_.size(); ++i) {
    const auto& group = *groups_[static_cast<std::size_t>(agents_[i].group)];
    arrived_scratch_[i] = group.arrived(static_cast<int>(i)) ? 1 : 0;
    max_speed_scratch_[i] = group.max_speed(static_cast<int>(i));
  }
  recorder_->sample(t_, agents_, leaders_scratch_, arrived_scratch_, max_speed_scratch_);
  recorder_->set_contact_stops(contact_stops_);
  recorder_->set_knots(crowd_ ? crowd_->knots() : 0);
}

}  // namespace animrt::herd
