#include "animrt/controllers/herd/crowd.hpp"

#include <DetourCommon.h>
#include <DetourCrowd.h>
#include <DetourNavMeshQuery.h>
#include <DetourProximityGrid.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "animrt/controllers/herd/cell_index.hpp"
#include "animrt/controllers/herd/knot.hpp"
#include "animrt/controllers/herd/passage.hpp"

namespace animrt::herd {
namespace {

constexpr double kPassiveSpeed =
    10.0;  // passive agents are moved by velocity requests, never limited
constexpr double kResnapDistance = 0.5;  // a figure this far from its crowd agent is placed afresh
constexpr double kWaitRadius = 1.0;  // a figure waiting for a passage stands this near its place
constexpr double kQueueGap = 0.3;    // or this near another that stands waiting there
constexpr double kQueueReach = 2.5;  // within this of its place

// A uniform draw in [0, 1) from the top 53 bits: the same numbers on every
// standard library, unlike std::uniform_real_distribution.
double unit(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
}

}  // namespace

Crowd::Crowd(NavWorld& world, std::span<const Agent> agents, CrowdParams params)
    : world_(world), params_(params), grid_rows_(std::make_unique<CellIndex>()) {
  if (static_cast<int>(agents.size()) > params_.max_agents) {
    throw std::invalid_argument("crowd: more agents than max_agents");
  }
  double rmax = 0.0;
  for (const Agent& a : agents) rmax = std::max(rmax, a.radius);
  crowd_ = dtAllocCrowd();
  if (!crowd_ ||
      !crowd_->init(params_.max_agents, static_cast<float>(rmax + params_.avoidance_margin_m),
                    world_.navmesh())) {
    throw std::runtime_error("crowd: could not initialise the Detour crowd");
  }
  dtObstacleAvoidanceParams oa = *crowd_->getObstacleAvoidanceParams(0);
  oa.horizTime = static_cast<float>(params_.avoidance_horizon_s);
  crowd_->setObstacleAvoidanceParams(0, &oa);
  *crowd_->getEditableFilter(0) = world_.filter();

  active_.assign(agents.size(), false);
  has_target_.assign(agents.size(), false);
  target_.assign(agents.size(), Vec2{});
  synced_.assign(agents.size(), Vec2{});
  facing_.assign(agents.size(), Vec2{});
  asking_.assign(agents.size(), false);
  was_held_.assign(agents.size(), 0);
  hold_at_.assign(agents.size(), Vec2{});
  const std::size_t walls = world_.config().moving.size();
  wall_of_.assign(agents.size(), -1);
  wall_at_.assign(agents.size(), Vec2{});
  wall_decided_.assign(agents.size() * walls, 0);
  wall_drop_.assign(walls, 0);
  wall_was_down_.assign(walls, 0);
  // A moving wall closes a gap when both ends of its long side meet a
  // static wall or the ground's edge (no figure passes between).
  const NavWorldConfig& wc = world_.config();
  wall_gaps_.clear();
  for (const MovingObstacle& m : wc.moving) {
    const Box& b = m.footprint;
    const Vec2 ax = heading_vector(b.yaw_rad), ay{-ax.y, ax.x};
    const bool thin_x = b.size.x <= b.size.y;
    WallGap g;
    g.across = thin_x ? ax : ay;
    g.along = thin_x ? ay : ax;
    g.depth = 0.5 * std::min(b.size.x, b.size.y);
    g.half = 0.5 * std::max(b.size.x, b.size.y);
    const double pass = 2.0 * wc.agent_radius_m;
    g.closes_gap = true;
    for (const double end : {-g.half, g.half}) {
      const Vec2 e = b.center + g.along * end;
      bool shut = e.x - wc.bounds.xmin < pass || wc.bounds.xmax - e.x < pass ||
                  e.y - wc.bounds.ymin < pass || wc.bounds.ymax - e.y < pass;
      for (const Box& s : wc.walls) shut = shut || NavWorld::distance_to_box(e, s) < pass;
      g.closes_gap = g.closes_gap && shut;
    }
    wall_gaps_.push_back(g);
  }
  travelling_.assign(agents.size(), 0);
  backing_.assign(agents.size(), 0);
  eligible_.assign(agents.size(), 0);
  if (params_.knot_still_s > 0.0) {
    KnotParams kp;
    kp.still_s = params_.knot_still_s;
    kp.progress_m = params_.knot_progress_m;
    kp.link_m = params_.knot_link_m;
    kp.back_off_m = params_.knot_back_off_m;
    kp.back_off_s = params_.knot_back_off_s;
    knots_ = std::make_unique<KnotRules>(agents.size(), kp);
  }
  if (params_.passage_width_radii > 0.0) {
    PassageParams pp;
    pp.max_width_radii = params_.passage_width_radii;
    pp.max_hold_s = params_.passage_max_hold_s;
    passages_ = std::make_unique<PassageRules>(world_.config().walls,
                                               rmax + params_.avoidance_margin_m, pp, &world_);
    if (passages_->empty()) passages_.reset();
  }
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const double r = agents[i].radius + params_.avoidance_margin_m;
    dtCrowdAgentParams ap{};
    ap.radius = static_cast<float>(r);
    ap.height = 1.0f;
    ap.maxAcceleration = 100.0f;
    ap.maxSpeed = static_cast<float>(kPassiveSpeed);
    // Detour looks at no more than 32 agents in the query square before
    // picking the nearest: a wide range in a dense crowd drops the agents
    // that matter.
    ap.collisionQueryRange = static_cast<float>(params_.query_range_radii * r);
    ap.pathOptimizationRange = static_cast<float>(30 * r);
    ap.separationWeight = static_cast<float>(params_.separation_weight);
    ap.updateFlags = 0;
    const auto p = NavWorld::to_recast(agents[i].position);
    const int idx = crowd_->addAgent(p.data(), &ap);
    if (idx != static_cast<int>(i)) throw std::runtime_error("crowd: could not add an agent");
  }
  // A member's plan reads the agents in its grid query (the cell span of
  // its query range) and, through the collision pushes of the crowd's four
  // passes, the neighbours of its neighbours three links away, each
  // chosen by its own grid query; keep-right reads a wider square. A rule
  // that reads the crowd's agents farther out must widen this reach.
  const double r = rmax + params_.avoidance_margin_m;
  const double hop = params_.query_range_radii * r;
  const double cell = crowd_->getGrid()->getCellSize();
  const double box = std::sqrt(2.0) * (hop + r + cell);
  const double ahead = std::sqrt(2.0) * (params_.keep_right_range_m + r + cell);
  reach_m_ = std::max(3 * hop + box, ahead) + 1.0;
  member_at_.reserve(agents.size());
  members_near_.reserve(agents.size());
  in_update_.reserve(agents.size());
}

Crowd::~Crowd() { dtFreeCrowd(crowd_); }

void Crowd::make_active(int i, double max_speed) {
  dtCrowdAgentParams ap = crowd_->getAgent(i)->params;
  ap.maxSpeed = static_cast<float>(max_speed);
  ap.maxAcceleration =
      static_cast<float>(std::max(max_speed * params_.figure_turn_rad_s * params_.accel_factor,
                                  params_.figure_start_speed_m_s / params_.step_s));
  ap.updateFlags = DT_CROWD_ANTICIPATE_TURNS | DT_CROWD_OBSTACLE_AVOIDANCE | DT_CROWD_OPTIMIZE_VIS |
                   DT_CROWD_OPTIMIZE_TOPO;
  if (params_.separation_weight > 0.0) ap.updateFlags |= DT_CROWD_SEPARATION;
  ap.obstacleAvoidanceType = 0;
  crowd_->updateAgentParameters(i, &ap);
  crowd_->resetMoveTarget(i);
  active_[static_cast<std::size_t>(i)] = true;
}

bool Crowd::request_target(int i, Vec2 target) {
  const auto p = NavWorld::to_recast(target);
  const float ext[3] = {1.0f, 2.0f, 1.0f};
  dtPolyRef ref = 0;
  float nearest[3];
  world_.query()->findNearestPoly(p.data(), ext, &world_.filter(), &ref, nearest);
  const auto k = static_cast<std::size_t>(i);
  if (!has_target_[k] || norm(target - target_[k]) > 1e-9) {
    // A new target (a slot swapped while travelling): whether to wait for
    // a moving wall is decided again for it, and a wait already begun
    // sends the member back to the wall's face.
    std::fill_n(wall_decided_.begin() + static_cast<std::ptrdiff_t>(k * wall_gaps_.size()),
                wall_gaps_.size(), 0);
    if (wall_of_[k] >= 0) {
      wall_of_[k] = -1;
      was_held_[k] = 0;
    }
  }
  has_target_[k] = true;
  target_[k] = target;
  return ref && crowd_->requestMoveTarget(i, ref, nearest);
}

void Crowd::stop(int i) {
  crowd_->resetMoveTarget(i);
  has_target_[static_cast<std::size_t>(i)] = false;
}

void Crowd::sync(int i, const Agent& a) {
  dtCrowdAgent* ag = crowd_->getEditableAgent(i);
  const auto p = NavWorld::to_recast(a.position);
  dtNavMeshQuery* q = world_.query();
  const dtQueryFilter* f = &world_.filter();
  bool placed =
      ag->state == DT_CROWDAGENT_STATE_WALKING && q->isValidPolyRef(ag->corridor.getFirstPoly(), f);
  if (placed) {
    // Slide along the mesh from where the crowd put the agent to where the
    // figure really is: the corridor stays valid and the agent stays on the
    // mesh even when the figure has strayed a little off it.
    ag->corridor.movePosition(p.data(), q, f);
    dtVcopy(ag->npos, ag->corridor.getPos());
    const float dx = ag->npos[0] - p[0], dz = ag->npos[2] - p[2];
    placed = dx * dx + dz * dz <= kResnapDistance * kResnapDistance;
  }
  if (!placed) {
    const float ext[3] = {1.0f, 2.0f, 1.0f};
    dtPolyRef ref = 0;
    float nearest[3];
    q->findNearestPoly(p.data(), ext, f, &ref, nearest);
    if (!ref) {
      ag->state = DT_CROWDAGENT_STATE_INVALID;
      return;
    }
    ag->corridor.reset(ref, nearest);
    ag->boundary.reset();
    ag->state = DT_CROWDAGENT_STATE_WALKING;
    dtVcopy(ag->npos, nearest);
    if (active_[static_cast<std::size_t>(i)] && has_target_[static_cast<std::size_t>(i)]) {
      request_current(i);
    }
  }
  const auto v = NavWorld::to_recast(facing_[static_cast<std::size_t>(i)] * a.speed);
  dtVcopy(ag->vel, v.data());
  if (!active_[static_cast<std::size_t>(i)]) crowd_->requestMoveVelocity(i, v.data());
}

void Crowd::step(double t, double dt, std::span<const Agent> agents) {
  if (stepped_ && t == last_t_) return;
  if (agents.size() != active_.size()) throw std::invalid_argument("crowd: the herd changed size");
  stepped_ = true;
  last_t_ = t;
  world_.update(t, agents);
  for (std::size_t i = 0; i < agents.size(); ++i) {
    facing_[i] = heading_vector(agents[i].heading);  // read again by keep_right
    sync(static_cast<int>(i), agents[i]);
    synced_[i] = NavWorld::from_recast(crowd_->getAgent(static_cast<int>(i))->npos);
  }
  if (passages_ || !world_.config().moving.empty()) apply_passages(t, agents);
  if (knots_) apply_knots(t, agents);
  select_participants();
  // The crowd registers each agent of its update in its grid as it stands now.
  grid_rows_->begin(crowd_->getGrid()->getCellSize());
  for (const int i : in_update_) {
    const dtCrowdAgent* ag = crowd_->getAgent(i);
    const float r = ag->params.radius;
    grid_rows_->add(i, ag->npos[0] - r, ag->npos[2] - r, ag->npos[0] + r, ag->npos[2] + r);
  }
  grid_rows_->finish();
  crowd_->update(static_cast<float>(dt), nullptr);
  dt_ = dt;
}

void Crowd::select_participants() {
  // Passive agents farther than reach_m_ from every member leave the
  // crowd's update: nothing of theirs reaches a member's plan, yet Detour
  // gives each a neighbour query, a move along the mesh and the collision
  // passes. They are still synced every step, so they rejoin in place.
  member_at_.clear();
  for (std::size_t i = 0; i < active_.size(); ++i) {
    if (active_[i]) member_at_.push_back(synced_[i]);
  }
  if (!member_at_.empty()) members_near_.build(std::span<const Vec2>(member_at_), reach_m_);
  in_update_.clear();
  for (std::size_t i = 0; i < active_.size(); ++i) {
    const bool take =
        active_[i] || (!member_at_.empty() && members_near_.any_within(synced_[i], reach_m_));
    crowd_->getEditableAgent(static_cast<int>(i))->active = take;
    if (take) in_update_.push_back(static_cast<int>(i));
  }
}

long Crowd::knots() const { return knots_ ? knots_->knots() : 0; }

bool Crowd::request_current(int i) {
  const auto k = static_cast<std::size_t>(i);
  if (backing_[k]) return retarget(i, knots_->back_off_point(i));
  if (was_held_[k]) return retarget(i, hold_at_[k]);
  return request_target(i, target_[k]);
}

void Crowd::apply_knots(double t, std::span<const Agent> agents) {
  // Only members whose plan asks them to walk (at half their top speed or
  // more, before avoidance): one that the plan stands (no way open, as at
  // a closed gate) waits, and is no knot.
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const dtCrowdAgent* ag = crowd_->getAgent(static_cast<int>(i));
    const bool asks = dtVlen(ag->dvel) >= 0.5f * ag->params.maxSpeed;
    eligible_[i] = travelling_[i] && active_[i] && has_target_[i] && !was_held_[i] && asks ? 1 : 0;
  }
  knots_->update(t, agents, target_, eligible_);
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const int k = static_cast<int>(i);
    const char backing = knots_->backing_off(k) && active_[i] && has_target_[i] ? 1 : 0;
    if (backing == backing_[i]) continue;
    backing_[i] = backing;
    request_current(k);
  }
}

bool Crowd::retarget(int i, Vec2 target) {
  const auto p = NavWorld::to_recast(target);
  const float ext[3] = {1.0f, 2.0f, 1.0f};
  dtPolyRef ref = 0;
  float nearest[3];
  world_.query()->findNearestPoly(p.data(), ext, &world_.filter(), &ref, nearest);
  return ref && crowd_->requestMoveTarget(i, ref, nearest);
}

void Crowd::apply_passages(double t, std::span<const Agent> agents) {
  for (std::size_t i = 0; i < agents.size(); ++i) asking_[i] = active_[i] && has_target_[i];
  if (passages_) passages_->update(t, agents, target_, asking_);
  for (std::size_t w = 0; w < wall_drop_.size(); ++w) {
    const char down = world_.obstacle_down(w) ? 1 : 0;
    if (down && !wall_was_down_[w]) ++wall_drop_[w];
    wall_was_down_[w] = down;
  }
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const int k = static_cast<int>(i);
    // A passage's rule first: it decides who goes through a narrow gap.
    Vec2 at;
    char held = 0;
    if (passages_ && passages_->held(k)) {
      held = 1;
      at = passages_->hold_point(k);
    } else if (asking_[i] && wait_for_wall(t, k, agents, at)) {
      held = 1;
    }
    if (backing_[i]) {  // backing off out of a knot first; the knot rules send it on after
      if (held) hold_at_[i] = at;
    } else if (held && (!was_held_[i] || norm(at - hold_at_[i]) > 1e-9)) {
      retarget(k, at);
      hold_at_[i] = at;
    } else if (!held && was_held_[i] && has_target_[i]) {
      retarget(k, target_[i]);
    }
    was_held_[i] = held;
  }
}

bool Crowd::wait_for_wall(double t, int i, std::span<const Agent> agents, Vec2& at) {
  // A moving wall that drops into a gap sends every plan through that gap
  // the long way round, and when it rises, back: slow figures swung from
  // one gap to the other and back every few seconds, near the wall (where
  // the two ways part widely) they made no headway, and those the drop
  // had turned jammed the other gap. The wall rises on its schedule, so a
  // member whose way through the gap (walking to the wall's near face,
  // waiting there till it rises, on from its far face) is quicker than
  // the way round walks to the near face and waits there. Decided once
  // per member and drop; while no way round leads on (a closed gate), the
  // plan stands it as before. Only for a wall that closes a gap between
  // walls: one standing free is walked round in a few strides, and a
  // pony sent to its face to wait turned there slowly, stood at a wall
  // corner on the way and lost more than the way round costs.
  const auto k = static_cast<std::size_t>(i);
  const auto& walls = world_.config().moving;
  int& of = wall_of_[k];
  if (of >= 0 && world_.obstacle_down(static_cast<std::size_t>(of))) {
    at = wall_at_[k];
    return true;
  }
  of = -1;
  const Agent& a = agents[k];
  const double speed = crowd_->getAgent(i)->params.maxSpeed;
  for (std::size_t w = 0; w < walls.size() && of < 0; ++w) {
    int& decided = wall_decided_[k * walls.size() + w];
    const WallGap& g = wall_gaps_[w];
    if (!g.closes_gap || !world_.obstacle_down(w) || decided == wall_drop_[w]) continue;
    decided = wall_drop_[w];
    const MovingObstacle& m = walls[w];
    const Box& b = m.footprint;
    // Through the box along its thin side.
    const Vec2 n = g.across, along = g.along;
    const double depth = g.depth, half = g.half;
    const double r = a.radius + params_.avoidance_margin_m;
    const double clear = depth + r + 0.15;  // off the mesh the wall carves
    const Vec2 d = a.position - b.center;
    const double side = dot(d, n) < 0.0 ? -1.0 : 1.0;
    const double reach = std::max(half - r, 0.0);
    const double lateral = std::clamp(dot(d, along), -reach, reach);
    const Vec2 near = b.center + n * (side * clear) + along * lateral;
    const Vec2 far = near - n * (side * 2.0 * clear);
    const auto round = world_.path_length(a.position, target_[k]);
    if (!round) continue;
    const auto to = world_.path_length(a.position, near);
    const auto on = world_.path_length(far, target_[k]);
    if (!to || !on || !(speed > 0.0)) continue;
    const double rises_in = std::max(0.0, m.down_fraction * m.period_s - m.time_in_period(t));
    const double through = std::max(*to / speed, rises_in) + (2.0 * clear + *on) / speed;
    if (through >= *round / speed) continue;
    of = static_cast<int>(w);
    wall_at_[k] = near;
  }
  if (of < 0) return false;
  at = wall_at_[k];
  return true;
}

Vec2 Crowd::passage_wait(int i, Vec2 v, std::span<const Agent> agents) const {
  const auto k = static_cast<std::size_t>(i);
  if (!was_held_[k] || backing_[k]) return v;
  const Agent& a = agents[k];
  const double here = norm(a.position - hold_at_[k]);
  if (here < kWaitRadius) return {};
  // A queue: standing where it meets a waiting figure that stands nearer
  // the place (only near it: elsewhere the figures it meets may be in the
  // way out, and standing for each other they would never leave).
  if (here > kQueueReach) return v;
  const dtCrowdAgent* ag = crowd_->getAgent(i);
  for (int n = 0; n < ag->nneis; ++n) {
    const auto j = static_cast<std::size_t>(ag->neis[n].idx);
    const Agent& b = agents[j];
    if (!was_held_[j] || b.speed != 0.0 || norm(hold_at_[j] - hold_at_[k]) > 1e-9) continue;
    if (norm(b.position - hold_at_[k]) >= here) continue;
    if (norm(b.position - a.position) < a.radius + b.radius + kQueueGap) return {};
  }
  return v;
}

Vec2 Crowd::planned_velocity(int i, bool unstick) const {
  const dtCrowdAgent* ag = crowd_->getAgent(i);
  if (ag->state != DT_CROWDAGENT_STATE_WALKING || !(dt_ > 0.0)) return {};
  // The step the crowd took, collision resolution included: overlapping
  // agents are pushed apart by position, not by velocity, and that push
  // is lost unless the figures walk it.
  Vec2 v = (NavWorld::from_recast(ag->npos) - synced_[static_cast<std::size_t>(i)]) / dt_;
  const Vec2 want = NavWorld::from_recast(ag->dvel);
  // A step too short for the figure to walk (under half its slowest walk,
  // as a collision push often is) leaves it standing just as well.
  const double walkable = 0.5 * params_.figure_start_speed_m_s;
  if (!unstick || (norm(v) >= 0.2 * norm(want) && norm(v) >= walkable)) return v;
  // Stalled: agents resting exactly at contact make every sampled velocity
  // look like a collision but standing still, so they would never move
  // again. Follow the path instead, less any part that closes on a
  // neighbour in contact: the agent slides along them.
  v = want;
  const Vec2 p = synced_[static_cast<std::size_t>(i)];
  for (int k = 0; k < ag->nneis; ++k) {
    const dtCrowdAgent* nb = crowd_->getAgent(ag->neis[k].idx);
    const Vec2 q = NavWorld::from_recast(nb->npos);
    const double contact = ag->params.radius + nb->params.radius + 0.05;
    if (norm(p - q) > contact) continue;
    const Vec2 n = normalized(p - q);
    const double in = dot(v, n);
    if (in < 0.0) v -= n * in;
  }
  return v;
}

Vec2 Crowd::safe_velocity(int i, Vec2 v, std::span<const Agent> agents) const {
  // The figures follow the plan late (a gait turns at a bounded rate and
  // walks where it faces), so near contact the plan must not close on a
  // neighbour at all: neither by its own direction nor by the figure
  // walking along a heading that still points at the neighbour (then it
  // only turns, in place).
  const dtCrowdAgent* ag = crowd_->getAgent(i);
  const Agent& a = agents[static_cast<std::size_t>(i)];
  const Vec2 h = facing_[static_cast<std::size_t>(i)];
  for (int k = 0; k < ag->nneis; ++k) {
    const Agent& b = agents[static_cast<std::size_t>(ag->neis[k].idx)];
    const Vec2 d = b.position - a.position;
    const double dist = norm(d);
    if (dist > a.radius + b.radius + params_.contact_margin_m || dist <= 0.0) continue;
    const Vec2 n = d / dist;
    const double closing = dot(v, n);
    if (closing > 0.0) v -= n * closing;
    if (dot(h, n) > 0.0) {
      const double forward = dot(v, h);
      if (forward > 0.0) v -= h * forward;
    }
  }
  return v;
}

int Crowd::near_agents(Vec2 p, double range, std::span<unsigned short> out) const {
  const auto c = NavWorld::to_recast(p);
  const float r = static_cast<float>(range);
  if (grid_rows_->query(c[0] - r, c[2] - r, c[0] + r, c[2] + r, out.size(), near_scratch_)) {
    std::copy(near_scratch_.begin(), near_scratch_.end(), out.begin());
    return static_cast<int>(near_scratch_.size());
  }
  // The grid's own ids count the agents of the update in order.
  const int n = crowd_->getGrid()->queryItems(c[0] - r, c[2] - r, c[0] + r, c[2] + r, out.data(),
                                              static_cast<int>(out.size()));
  for (int k = 0; k < n; ++k) {
    const auto id = out[static_cast<std::size_t>(k)];
    out[static_cast<std::size_t>(k)] = static_cast<unsigned short>(in_update_[id]);
  }
  return n;
}

Vec2 Crowd::keep_right(int i, Vec2 v, std::span<const Agent> agents) const {
  const double speed = norm(v);
  if (params_.keep_right_rad <= 0.0 || speed <= 0.0) return v;
  const Agent& a = agents[static_cast<std::size_t>(i)];
  const Vec2 way = v / speed;
  const Vec2 right{way.y, -way.x};
  const double range = params_.keep_right_range_m;
  const double lane = 2.0 * (a.radius + params_.avoidance_margin_m);
  // Agents near the figure, from the crowd's own grid (built at its last update).
  std::array<unsigned short, 64> near{};
  const int n = near_agents(a.position, range, near);
  double urge = 0.0;  // 0..1: how hard to keep right
  for (int k = 0; k < n; ++k) {
    const int j = near[static_cast<std::size_t>(k)];
    if (j == i || static_cast<std::size_t>(j) >= agents.size()) continue;
    const Agent& b = agents[static_cast<std::size_t>(j)];
    const Vec2 d = b.position - a.position;
    const double ahead = dot(d, way);
    // Oncoming: ahead, within range, facing more than 120 degrees away
    // from this way, and in the lane (not already passing to the side).
    if (ahead <= 0.0 || ahead > range || dot(facing_[static_cast<std::size_t>(j)], way) > -0.5)
      continue;
    if (std::abs(dot(d, right)) >= lane) continue;
    urge = std::max(urge, 1.0 - ahead / range);
  }
  if (urge <= 0.0) return v;
  const double turn = -params_.keep_right_rad * urge;  // negative: to the right
  const double c = std::cos(turn), s = std::sin(turn);
  const Vec2 turned{v.x * c - v.y * s, v.x * s + v.y * c};
  // In the open only: near a wall the crowd's own plan keeps clear of it.
  const Vec2 probe = a.position + turned / speed * lane;
  if (world_.in_wall(a.position, a.radius + lane) || world_.in_wall(probe, a.radius + lane) ||
      !world_.on_mesh(probe, a.radius))
    return v;
  return turned;
}

CrowdGroup::CrowdGroup(Crowd& crowd, std::span<const Agent> agents, std::vector<int> members,
                       CrowdGroupParams params)
    : crowd_(crowd), members_(std::move(members)), params_(params) {
  if (!(params_.speed_min_mps > 0.0 && params_.speed_max_mps >= params_.speed_min_mps)) {
    throw std::invalid_argument("crowd group: speeds must satisfy 0 < min <= max");
  }
  std::mt19937_64 rng(params_.seed);
  double rmax = 0.0;
  for (int m : members_) {
    if (m < 0 || static_cast<std::size_t>(m) >= agents.size()) {
      throw std::invalid_argument("crowd group: member index out of range");
    }
    const double v =
        params_.speed_min_mps + (params_.speed_max_mps - params_.speed_min_mps) * unit(rng);
    max_speed_.push_back(v);
    rmax = std::max(rmax, agents[static_cast<std::size_t>(m)].radius);
    crowd_.make_active(m, v);
    crowd_.request_target(m, params_.target);
  }
  state_.assign(members_.size(), State::kTravelling);
  to_slot_.reserve(members_.size());
  slot_of_.assign(members_.size(), -1);
  candidate_.assign(members_.size(), -1);
  stall_since_.assign(members_.size(), 0.0);
  for (int m : members_) stall_anchor_.push_back(agents[static_cast<std::size_t>(m)].position);
  headway_goal_.assign(members_.size(), params_.target);
  headway_best_.assign(members_.size(), std::numeric_limits<double>::infinity());
  headway_since_.assign(members_.size(), 0.0);
  is_member_.assign(agents.size(), 0);
  for (int m : members_) is_member_[static_cast<std::size_t>(m)] = 1;
  make_slots(rmax + crowd_.params().avoidance_margin_m);
}

void CrowdGroup::find_lanes(std::span<const Agent> agents) {
  // A figure of another group still on its way where this group gathers
  // (its target lies there, or the figure waits there for a gap, or it
  // was pushed there) gets a lane, as wide as itself and three halves of
  // a spacing, toward its target (not where it is sent for now: backing
  // off a knot or waiting for a gap, it goes on that way after): slots in
  // it are not taken, nor does a member gather in it, while the figure is
  // there, so the gathering does not close round it for good.
  lanes_.clear();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    if (is_member_[i] || !crowd_.active_[i] || !crowd_.travelling_[i] || !crowd_.has_target_[i])
      continue;
    const Vec2 p = agents[i].position;
    if (norm(p - params_.target) > assign_distance_) continue;
    const Vec2 to = crowd_.target_[i] - p;
    const double d = norm(to);
    if (!(d > 1e-6)) continue;
    lanes_.push_back(
        {p, to / d, std::min(d, 2.0 * assign_distance_), agents[i].radius + 0.75 * spacing_});
  }
}

void CrowdGroup::mark_lane_slots() {
  // Not the first slot (at the target): the gathering can always begin.
  for (const int open : open_) {
    const auto s = static_cast<std::size_t>(open);
    if (s > 0) in_lane_[s] = in_way_[s] || (!lanes_.empty() && in_lane(slots_[s])) ? 1 : 0;
  }
}

bool CrowdGroup::in_lane(Vec2 q) const {
  for (const Lane& l : lanes_) {
    const Vec2 r = q - l.from;
    const double u = dot(r, l.dir);
    if (u >= -0.5 * spacing_ && u <= l.length && std::abs(cross(l.dir, r)) < l.half_width)
      return true;
  }
  return false;
}

void CrowdGroup::make_slots(double radius) {
  const double s = params_.slot_spacing_m > 0.0 ? params_.slot_spacing_m : 2 * radius + 0.3;
  const NavWorld& w = crowd_.world();
  const Vec2 t = params_.target;
  // Hexagonal lattice around the target, nearest first; ties broken by
  // angle so the order never depends on floating-point noise in sorting.
  std::vector<std::pair<double, Vec2>> cand;
  const int n =
      static_cast<int>(std::ceil(std::sqrt(6.0 * static_cast<double>(members_.size())))) + 3;
  for (int j = -n; j <= n; ++j) {
    for (int i = -n; i <= n; ++i) {
      const Vec2 q = t + Vec2{(i + 0.5 * j) * s, j * s * std::sqrt(3.0) / 2};
      cand.push_back({norm(q - t), q});
    }
  }
  std::sort(cand.begin(), cand.end(), [&](const auto& a, const auto& b) {
    if (std::abs(a.first - b.first) > 1e-9) return a.first < b.first;
    return std::atan2(a.second.y - t.y, a.second.x - t.x) <
           std::atan2(b.second.y - t.y, b.second.x - t.x);
  });
  for (const auto& [d, q] : cand) {
    // Room for a lopsided gathering: it grows toward where its members
    // come from.
    if (slots_.size() >= 6 * members_.size()) break;
    if (!w.on_mesh(q, 0.01) || w.in_wall(q, radius)) continue;
    bool under_obstacle = false;
    for (const MovingObstacle& m : w.config().moving) {
      if (NavWorld::distance_to_box(q, m.footprint) < radius + w.config().agent_radius_m)
        under_obstacle = true;
    }
    if (under_obstacle) continue;
    // Only slots reached from the target roughly in a straight line: not
    // behind a wall.
    const auto len = w.path_length(t, q);
    if (!len || *len > d + s) continue;
    slots_.push_back(q);
  }
  // No member gathers in a narrow passage or its doorways: gathered
  // there, a team stands in the way of every figure that must pass. The
  // slots stay in the lattice, never taken (like slots in a lane), so the
  // gathering's reach is what it would be without the passage.
  in_way_.assign(slots_.size(), 0);
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    if (crowd_.passages_ && crowd_.passages_->in_way(slots_[k], radius)) in_way_[k] = 1;
  }
  slot_taken_.assign(slots_.size(), false);
  frontier_.assign(slots_.size(), false);
  open_.clear();
  open_.reserve(slots_.size());
  taken_.reserve(slots_.size());
  if (!frontier_.empty()) {
    frontier_[0] = true;
    open_.push_back(0);
  }
  neighbours_.assign(slots_.size(), {});
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    for (std::size_t j = 0; j < slots_.size(); ++j) {
      if (i != j && norm(slots_[i] - slots_[j]) < 1.1 * s)
        neighbours_[i].push_back(static_cast<int>(j));
    }
  }
  spacing_ = s;
  const double extent = slots_.empty() ? 0.0 : norm(slots_.back() - t);
  assign_distance_ = params_.assign_distance_m > 0.0 ? params_.assign_distance_m : extent + 2 * s;
}

void CrowdGroup::take_slot(std::size_t slot) {
  slot_taken_[slot] = true;
  const auto at = std::find(open_.begin(), open_.end(), static_cast<int>(slot));
  if (at != open_.end()) open_.erase(at);
  taken_.push_back(static_cast<int>(slot));
  for (const int n : neighbours_[slot]) {
    const auto m = static_cast<std::size_t>(n);
    if (frontier_[m]) continue;
    frontier_[m] = true;
    if (!slot_taken_[m]) open_.insert(std::lower_bound(open_.begin(), open_.end(), n), n);
  }
}

void CrowdGroup::free_slot(std::size_t slot) {
  slot_taken_[slot] = false;
  const int s = static_cast<int>(slot);
  const auto at = std::find(taken_.begin(), taken_.end(), s);
  if (at != taken_.end()) taken_.erase(at);
  const auto to = std::lower_bound(open_.begin(), open_.end(), s);
  if (frontier_[slot] && (to == open_.end() || *to != s)) open_.insert(to, s);
}

bool CrowdGroup::reachable(Vec2 from, std::size_t slot) const {
  // The straight walk from `from` to the slot keeps clear of every taken
  // slot (but the slot's neighbours may be grazed at the very end).
  const Vec2 to = slots_[slot];
  const Vec2 d = to - from;
  const double len2 = norm2(d);
  for (const int taken : taken_) {
    const auto s = static_cast<std::size_t>(taken);
    const double u = len2 > 0.0 ? std::clamp(dot(slots_[s] - from, d) / len2, 0.0, 1.0) : 0.0;
    if (norm(from + d * u - slots_[s]) < 0.7 * spacing_) return false;
  }
  return true;
}

std::size_t CrowdGroup::arrived_count() const {
  return static_cast<std::size_t>(std::count(state_.begin(), state_.end(), State::kArrived));
}

void CrowdGroup::steer(double t, double dt, std::span<const Agent> agents,
                       std::span<Vec2> desired) {
  // The gathering grows from the target outward: a travelling member near
  // the target heads for a free slot at the gathering's edge (next to a
  // taken slot, or the slot at the target) that it can walk to in a
  // straight line past the taken ones, nearest the target first and then
  // on its own side; it takes the slot once it is next to it. Arrivals so
  // settle on the side they come from and never walk through the members
  // already standing, and no slot is held by a member that cannot reach it.
  // Slots in another group's lane are not taken (find_lanes).
  const Vec2 target = params_.target;
  find_lanes(agents);
  in_lane_.assign(slots_.size(), 0);
  mark_lane_slots();
  for (std::size_t k = 0; k < members_.size(); ++k) {
    if (state_[k] != State::kTravelling) continue;
    const int m = members_[k];
    const Vec2 p = agents[static_cast<std::size_t>(m)].position;
    if (norm(p - target) > assign_distance_) continue;
    int best = -1;
    double best_cost = std::numeric_limits<double>::infinity(), kept_cost = best_cost;
    for (const int open : open_) {
      const auto s = static_cast<std::size_t>(open);
      if (in_lane_[s]) continue;
      const double cost = norm(slots_[s] - target) + 0.5 * norm(slots_[s] - p);
      if (static_cast<int>(s) == candidate_[k]) kept_cost = cost;
      if (cost < best_cost && reachable(p, s)) {
        best_cost = cost;
        best = static_cast<int>(s);
      }
    }
    if (best < 0) {
      // Nothing reachable in a straight line: the best edge slot anyway,
      // never the target itself, which a slot holder may be heading for.
      for (const int open : open_) {
        const auto s = static_cast<std::size_t>(open);
        if (in_lane_[s]) continue;
        const double cost = norm(slots_[s] - target) + 0.5 * norm(slots_[s] - p);
        if (static_cast<int>(s) == candidate_[k]) kept_cost = cost;
        if (cost < best_cost) {
          best_cost = cost;
          best = static_cast<int>(s);
        }
      }
    }
    if (kept_cost > best_cost + 0.3 * spacing_) {  // hysteresis: no flapping between equals
      candidate_[k] = best;
      crowd_.request_target(m, best >= 0 ? slots_[static_cast<std::size_t>(best)] : target);
    }
    const int c = candidate_[k];
    if (c >= 0 && !in_lane_[static_cast<std::size_t>(c)] &&
        norm(slots_[static_cast<std::size_t>(c)] - p) < spacing_) {
      const auto b = static_cast<std::size_t>(c);
      take_slot(b);
      mark_lane_slots();  // the slots it opened
      slot_of_[k] = c;
      state_[k] = State::kToSlot;
      for (std::size_t j = 0; j < members_.size(); ++j) {
        if (j != k && candidate_[j] == c) candidate_[j] = -1;
      }
    }
  }
  // A travelling member standing on a slot whose holder has not arrived
  // takes it over, and the holder looks again: otherwise each waits for
  // the other. The holders are listed first, in member order, and a member
  // that takes a slot over joins the list.
  to_slot_.clear();
  for (std::size_t k = 0; k < members_.size(); ++k) {
    if (state_[k] == State::kToSlot) to_slot_.push_back(k);
  }
  for (std::size_t k = 0; k < members_.size() && !to_slot_.empty(); ++k) {
    if (state_[k] != State::kTravelling) continue;
    const Vec2 p = agents[static_cast<std::size_t>(members_[k])].position;
    for (const std::size_t j : to_slot_) {
      if (state_[j] != State::kToSlot) continue;  // it gave its slot up
      const Vec2 slot = slots_[static_cast<std::size_t>(slot_of_[j])];
      const Vec2 q = agents[static_cast<std::size_t>(members_[j])].position;
      if (norm(p - slot) < 0.5 * spacing_ && norm(p - slot) < norm(q - slot) && !in_lane(slot)) {
        slot_of_[k] = slot_of_[j];
        state_[k] = State::kToSlot;
        crowd_.request_target(members_[k], slot);
        slot_of_[j] = -1;
        candidate_[j] = -1;
        state_[j] = State::kTravelling;
        crowd_.request_target(members_[j], target);
        const auto at = std::lower_bound(to_slot_.begin(), to_slot_.end(), k);
        if (at == to_slot_.end() || *at != k) to_slot_.insert(at, k);
        break;
      }
    }
  }
  for (std::size_t k = 0; k < members_.size(); ++k) {
    const Vec2 p = agents[static_cast<std::size_t>(members_[k])].position;
    // A member also arrives when it stands within half a spacing of its
    // slot: the crowd slows a member down as it nears its goal, and a
    // figure whose slowest walk is fast stands once the plan is under half
    // of it, short of the slot.
    const double to_slot =
        state_[k] == State::kToSlot ? norm(p - slots_[static_cast<std::size_t>(slot_of_[k])]) : 0.0;
    const bool standing = agents[static_cast<std::size_t>(members_[k])].speed == 0.0;
    if (state_[k] == State::kToSlot &&
        (to_slot < params_.arrive_tolerance_m || (standing && to_slot < 0.5 * spacing_))) {
      state_[k] = State::kArrived;
      crowd_.stop(members_[k]);
      continue;
    }
    if (state_[k] == State::kArrived) continue;
    if (norm(p - stall_anchor_[k]) > 0.1) {
      stall_anchor_[k] = p;
      stall_since_[k] = t;
    }
    // A member that has come no closer to where it is going (its slot, the
    // slot it heads for, or the target) for stall_time_s next to the
    // gathering (within a spacing and a half of an arrived member) has
    // gathered where it stands; its slot, if it held one, is free again.
    // Standing still is one way of making no headway; being jostled to and
    // fro between the members standing round it, or circling a slot that
    // lies inside the figure's turning circle, are others. One pushed back
    // by more than half a spacing starts afresh from there: walking back,
    // it makes headway again.
    const int heading_for = slot_of_[k] >= 0 ? slot_of_[k] : candidate_[k];
    const Vec2 goal = heading_for >= 0 ? slots_[static_cast<std::size_t>(heading_for)] : target;
    const double to_goal = norm(p - goal);
    if (norm(goal - headway_goal_[k]) > 1e-9 || to_goal < headway_best_[k] - 0.1 ||
        to_goal > headway_best_[k] + 0.5 * spacing_) {
      headway_goal_[k] = goal;
      headway_best_[k] = to_goal;
      headway_since_[k] = t;
      continue;
    }
    if (params_.stall_time_s <= 0.0 || t - headway_since_[k] < params_.stall_time_s) continue;
    bool beside = false;
    for (std::size_t j = 0; j < members_.size() && !beside; ++j) {
      beside = state_[j] == State::kArrived &&
               norm(agents[static_cast<std::size_t>(members_[j])].position - p) < 1.5 * spacing_;
    }
    if (!beside || in_lane(p)) continue;  // not in another group's way out
    if (slot_of_[k] >= 0) free_slot(static_cast<std::size_t>(slot_of_[k]));
    slot_of_[k] = -1;
    state_[k] = State::kArrived;
    crowd_.stop(members_[k]);
  }
  for (std::size_t k = 0; k < members_.size(); ++k) {
    crowd_.set_travelling(members_[k], state_[k] != State::kArrived);
  }
  crowd_.step(t, dt, agents);
  for (std::size_t k = 0; k < members_.size(); ++k) {
    const int m = members_[k];
    desired[static_cast<std::size_t>(m)] =
        state_[k] == State::kArrived
            ? Vec2{}
            : crowd_.safe_velocity(
                  m,
                  crowd_.passage_wait(
                      m,
                      crowd_.keep_right(
                          m,
                          crowd_.planned_velocity(
                              m, crowd_.params().unstick &&
                                     (norm(agents[static_cast<std::size_t>(m)].position - target) <
                                          assign_distance_ ||
                                      (crowd_.params().unstick_after_s > 0.0 &&
                                       t - stall_since_[k] >= crowd_.params().unstick_after_s))),
                          agents),
                      agents),
                  agents);
  }
}

}  // namespace animrt::herd
