#include "animrt/controllers/herd/passage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include "animrt/controllers/herd/nav_world.hpp"

namespace animrt::herd {
namespace {

int idx(int dir) { return dir > 0 ? 0 : 1; }
// A passage's waiting places: way +1 right, left; way -1 right, left.
std::size_t place_slot(int dir, int side) {
  return static_cast<std::size_t>(2 * idx(dir) + (side > 0 ? 0 : 1));
}
constexpr signed char kNotThrough = 2;  // the figure's way does not lead through the passage
// A figure round a corner from a passage nearer its mouth than this (by
// the mesh) when its way must wait walks on round the corner.
constexpr double kRoundGoesOnM = 3.0;

// A box's extent on the ground when it is axis-aligned (yaw a multiple of
// 90 degrees); false for any other yaw.
bool aligned_extent(const Box& b, Rect& r) {
  const double q = std::remainder(b.yaw_rad, M_PI / 2);
  if (std::abs(q) > 1e-6) return false;
  const bool swapped = std::abs(std::remainder(b.yaw_rad, M_PI)) > M_PI / 4;
  const double hx = (swapped ? b.size.y : b.size.x) / 2, hy = (swapped ? b.size.x : b.size.y) / 2;
  r = {b.center.x - hx, b.center.y - hy, b.center.x + hx, b.center.y + hy};
  return true;
}

// A box turned by a multiple of 90 degrees takes its corners and extent
// from its extent on the ground, with no rounding of the turn, so gaps
// between such walls come out exact.
WallExtent extent_of(const Box& b) {
  WallExtent s;
  Rect r;
  if (aligned_extent(b, r)) {
    s.corner = {Vec2{r.xmin, r.ymin}, Vec2{r.xmax, r.ymin}, Vec2{r.xmax, r.ymax},
                Vec2{r.xmin, r.ymax}};
    s.ax = {1, 0};
    s.ay = {0, 1};
    s.a0 = r.xmin;
    s.a1 = r.xmax;
    s.b0 = r.ymin;
    s.b1 = r.ymax;
    return s;
  }
  s.ax = heading_vector(b.yaw_rad);
  s.ay = {-s.ax.y, s.ax.x};
  const Vec2 hx = s.ax * (b.size.x / 2), hy = s.ay * (b.size.y / 2);
  s.corner = {b.center - hx - hy, b.center + hx - hy, b.center + hx + hy, b.center - hx + hy};
  s.a0 = dot(b.center, s.ax) - b.size.x / 2;
  s.a1 = dot(b.center, s.ax) + b.size.x / 2;
  s.b0 = dot(b.center, s.ay) - b.size.y / 2;
  s.b1 = dot(b.center, s.ay) + b.size.y / 2;
  return s;
}

// The part [lo, hi] of the line q + dir * s inside one extent of a slab
// along axis n: false when the line misses it.
bool clip(Vec2 q, Vec2 dir, Vec2 n, double e0, double e1, double& lo, double& hi) {
  if (e0 > e1) return false;  // a wall thinner than the margin blocks() leaves
  const double k = dot(dir, n), q0 = dot(q, n);
  if (k == 0.0) return q0 >= e0 && q0 <= e1;
  double s0 = (e0 - q0) / k, s1 = (e1 - q0) / k;
  if (s0 > s1) std::swap(s0, s1);
  lo = std::max(lo, s0);
  hi = std::min(hi, s1);
  return lo <= hi;
}

// Where the line q + dir * s crosses the wall, as [lo, hi] in s.
bool line_through(const WallExtent& w, Vec2 q, Vec2 dir, double& lo, double& hi) {
  lo = -std::numeric_limits<double>::infinity();
  hi = std::numeric_limits<double>::infinity();
  return clip(q, dir, w.ax, w.a0, w.a1, lo, hi) && clip(q, dir, w.ay, w.b0, w.b1, lo, hi);
}

// Whether the segment from p to q passes through the wall's inside (a
// centimetre in from its faces: grazing a face or a corner is no block).
bool blocks(const WallExtent& w, Vec2 p, Vec2 q) {
  constexpr double kIn = 0.01;
  double lo = 0.0, hi = 1.0;
  const Vec2 d = q - p;
  return clip(p, d, w.ax, w.a0 + kIn, w.a1 - kIn, lo, hi) &&
         clip(p, d, w.ay, w.b0 + kIn, w.b1 - kIn, lo, hi) && lo < hi;
}

// Whether the segments ab and cd cross (touching counts).
bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const auto side = [](Vec2 o, Vec2 p, Vec2 q) { return cross(p - o, q - o); };
  const double s1 = side(a, b, c), s2 = side(a, b, d), s3 = side(c, d, a), s4 = side(c, d, b);
  return ((s1 <= 0.0 && s2 >= 0.0) || (s1 >= 0.0 && s2 <= 0.0)) &&
         ((s3 <= 0.0 && s4 >= 0.0) || (s3 >= 0.0 && s4 <= 0.0));
}

// Whether a path (its corners) crosses the passage's middle, from wall to
// wall.
bool crosses_middle(const Passage& p, const std::vector<Vec2>& path) {
  const Vec2 across{-p.axis.y, p.axis.x};
  const Vec2 a = p.centre - across * p.half_width, b = p.centre + across * p.half_width;
  for (std::size_t i = 1; i < path.size(); ++i) {
    if (segments_cross(path[i - 1], path[i], a, b)) return true;
  }
  return false;
}

Vec2 closest_on_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 d = b - a;
  const double l2 = norm2(d);
  const double u = l2 > 0.0 ? std::clamp(dot(p - a, d) / l2, 0.0, 1.0) : 0.0;
  return a + d * u;
}

// Whether two walls overlap (no axis of either separates them).
bool overlap(const WallExtent& a, const WallExtent& b) {
  for (const WallExtent* w : {&a, &b}) {
    for (const Vec2 n : {w->ax, w->ay}) {
      double a_lo = std::numeric_limits<double>::infinity(), a_hi = -a_lo, b_lo = a_lo,
             b_hi = -a_lo;
      for (const Vec2 c : a.corner) {
        a_lo = std::min(a_lo, dot(c, n));
        a_hi = std::max(a_hi, dot(c, n));
      }
      for (const Vec2 c : b.corner) {
        b_lo = std::min(b_lo, dot(c, n));
        b_hi = std::max(b_hi, dot(c, n));
      }
      if (a_hi <= b_lo || b_hi <= a_lo) return false;
    }
  }
  return true;
}

// The gap across between two walls on the line axis * t + across * s, and
// its middle; infinite where the line misses either wall or they overlap.
double gap_at(const WallExtent& a, const WallExtent& b, Vec2 axis, Vec2 across, double t,
              double* mid) {
  double a0, a1, b0, b1;
  const Vec2 q = axis * t;
  if (!line_through(a, q, across, a0, a1) || !line_through(b, q, across, b0, b1))
    return std::numeric_limits<double>::infinity();
  if (a1 <= b0) {
    if (mid) *mid = (a1 + b0) / 2;
    return b0 - a1;
  }
  if (b1 <= a0) {
    if (mid) *mid = (b1 + a0) / 2;
    return a0 - b1;
  }
  return std::numeric_limits<double>::infinity();
}

// The narrow gap between two walls at any angle: across it is the way
// between their nearest points, and it runs along the perpendicular as far
// as both walls face each other and the gap stays under max_width (for two
// parallel walls, their whole overlap; for slanted ones, the stretch round
// the narrowest point).
bool passage_between(const WallExtent& a, const WallExtent& b, double max_width, Passage& out) {
  if (overlap(a, b)) return false;
  double best = std::numeric_limits<double>::infinity();
  Vec2 pa, pb;
  for (int k = 0; k < 4; ++k) {
    for (int e = 0; e < 4; ++e) {
      const Vec2 qb = closest_on_segment(a.corner[k], b.corner[e], b.corner[(e + 1) % 4]);
      if (const double d = norm(qb - a.corner[k]); d < best) {
        best = d;
        pa = a.corner[k];
        pb = qb;
      }
      const Vec2 qa = closest_on_segment(b.corner[k], a.corner[e], a.corner[(e + 1) % 4]);
      if (const double d = norm(qa - b.corner[k]); d < best) {
        best = d;
        pa = qa;
        pb = b.corner[k];
      }
    }
  }
  if (!(best > 0.0) || best >= max_width) return false;
  Vec2 across = (pb - pa) / best;
  // Walls square to each other meet square: no rounding in the direction.
  if (std::abs(across.x) < 1e-9) across = {0, across.y > 0 ? 1.0 : -1.0};
  if (std::abs(across.y) < 1e-9) across = {across.x > 0 ? 1.0 : -1.0, 0};
  Vec2 axis{-across.y, across.x};
  if (axis.x < 0.0 || (axis.x == 0.0 && axis.y < 0.0)) axis = axis * -1.0;
  across = {-axis.y, axis.x};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const WallExtent* w : {&a, &b}) {
    double w_lo = std::numeric_limits<double>::infinity(), w_hi = -w_lo;
    for (const Vec2 c : w->corner) {
      w_lo = std::min(w_lo, dot(c, axis));
      w_hi = std::max(w_hi, dot(c, axis));
    }
    lo = w == &a ? w_lo : std::max(lo, w_lo);
    hi = w == &a ? w_hi : std::min(hi, w_hi);
  }
  if (!(hi > lo)) return false;
  // The narrowest point: the gap is convex along the axis (both walls
  // convex), flat between parallel faces, where the nearest points found
  // may sit at a corner, at the very end of the overlap.
  double pinch = std::clamp(dot(pa, axis), lo, hi);
  double narrowest = gap_at(a, b, axis, across, pinch, nullptr);
  for (double l = lo, h = hi; h - l > 1e-9 * (1.0 + std::abs(l));) {
    const double m0 = l + (h - l) / 3, m1 = h - (h - l) / 3;
    const double g0 = gap_at(a, b, axis, across, m0, nullptr);
    const double g1 = gap_at(a, b, axis, across, m1, nullptr);
    if (g0 < narrowest) {
      narrowest = g0;
      pinch = m0;
    }
    if (g1 < narrowest) {
      narrowest = g1;
      pinch = m1;
    }
    (g0 <= g1 ? h : l) = g0 <= g1 ? m1 : m0;
  }
  if (!(narrowest < max_width)) return false;
  // The gap widens away from its narrowest point (both walls convex): the
  // passage ends where it reaches max_width.
  const auto end = [&](double far) {
    if (gap_at(a, b, axis, across, far, nullptr) < max_width) return far;
    double in = pinch, beyond = far;
    for (int k = 0; k < 48; ++k) {
      const double m = (in + beyond) / 2;
      (gap_at(a, b, axis, across, m, nullptr) < max_width ? in : beyond) = m;
    }
    return in;
  };
  const double t0 = end(lo), t1 = end(hi);
  if (!(t1 > t0)) return false;
  const double t = (t0 + t1) / 2;
  double mid = 0.0;
  if (!std::isfinite(gap_at(a, b, axis, across, t, &mid))) return false;
  out = Passage{};
  out.centre = axis * t + across * mid;
  out.axis = axis;
  out.half_width = narrowest / 2;
  out.half_length = (t1 - t0) / 2;
  return true;
}

}  // namespace

std::vector<Passage> find_passages(std::span<const Box> walls, double max_width) {
  std::vector<WallExtent> w;
  for (const Box& b : walls) w.push_back(extent_of(b));
  std::vector<Passage> out;
  for (std::size_t i = 0; i < w.size(); ++i) {
    for (std::size_t j = i + 1; j < w.size(); ++j) {
      Passage p;
      if (passage_between(w[i], w[j], max_width, p)) out.push_back(p);
    }
  }
  return out;
}

std::vector<PassageChain> find_chains(
    std::span<const Passage> passages, double link_m,
    const std::function<std::optional<double>(Vec2, Vec2)>& distance) {
  // Mouth 2k + 0 is passage k's mouth along its axis, 2k + 1 against it.
  const std::size_t n = passages.size();
  const auto mouth = [&](std::size_t m) {
    const Passage& p = passages[m / 2];
    return p.centre + p.axis * ((m % 2 == 0 ? 1.0 : -1.0) * p.half_length);
  };
  const auto out_of = [&](std::size_t m) {  // the way out of the passage through mouth m
    return passages[m / 2].axis * (m % 2 == 0 ? 1.0 : -1.0);
  };
  std::vector<std::vector<std::size_t>> links(2 * n);
  for (std::size_t a = 0; a < 2 * n; ++a) {
    for (std::size_t b = a + 1; b < 2 * n; ++b) {
      if (a / 2 == b / 2) continue;
      const Vec2 gap = mouth(b) - mouth(a);
      // Each mouth faces the other: out of one is on toward the other
      // (gaps side by side in one wall face the same way, and do not link).
      const double along = norm(gap) * 0.1;
      if (dot(gap, out_of(a)) <= along || dot(gap * -1.0, out_of(b)) <= along) continue;
      const auto d = distance(mouth(a), mouth(b));
      if (d && *d <= link_m) {
        links[a].push_back(b);
        links[b].push_back(a);
      }
    }
  }
  // A mouth faced by more than one other (a junction) links none.
  const auto link_of = [&](std::size_t m) -> long {
    if (links[m].size() != 1) return -1;
    const std::size_t o = links[m][0];
    return links[o].size() == 1 ? static_cast<long>(o) : -1;
  };
  std::vector<char> taken(n, 0);
  std::vector<PassageChain> chains;
  for (std::size_t k = 0; k < n; ++k) {
    if (taken[k]) continue;
    // Walk back to one end of k's chain (a ring has none: it stays at k).
    std::size_t start = k, from = 2 * k + 1;  // entering `start` through mouth `from`
    for (std::size_t steps = 0; steps < n; ++steps) {
      const long back = link_of(from);
      if (back < 0 || static_cast<std::size_t>(back) / 2 == k) break;
      start = static_cast<std::size_t>(back) / 2;
      from = static_cast<std::size_t>(back) ^ 1U;
    }
    PassageChain c;
    std::size_t at = start, in = from;
    for (std::size_t steps = 0; steps < n && !taken[at]; ++steps) {
      taken[at] = 1;
      c.members.push_back(static_cast<int>(at));
      c.orient.push_back(in % 2 == 1 ? 1 : -1);  // in through its minus mouth: along its axis
      const long next = link_of(in ^ 1U);
      if (next < 0) break;
      at = static_cast<std::size_t>(next) / 2;
      in = static_cast<std::size_t>(next);
    }
    chains.push_back(std::move(c));
  }
  return chains;
}

PassageRules::PassageRules(std::span<const Box> walls, double avoid_radius, PassageParams params,
                           const NavWorld* world)
    : passages_(find_passages(walls, params.max_width_radii * avoid_radius)),
      avoid_radius_(avoid_radius),
      params_(params),
      world_(world) {
  for (const Box& b : walls) walls_.push_back(extent_of(b));
  chains_ = find_chains(passages_, params_.approach_m, [this](Vec2 a, Vec2 b) {
    return world_ ? world_->path_length(a, b) : std::optional<double>(norm(b - a));
  });
  chain_of_.assign(passages_.size(), 0);
  for (std::size_t c = 0; c < chains_.size(); ++c) {
    for (const int m : chains_[c].members)
      chain_of_[static_cast<std::size_t>(m)] = static_cast<int>(c);
  }
  places_.resize(passages_.size());
  for (std::size_t k = 0; k < passages_.size(); ++k) {
    for (const int dir : {1, -1}) {
      for (const int side : {1, -1})
        places_[k][place_slot(dir, side)] = find_wait_place(passages_[k], dir, side);
    }
  }
}

bool PassageRules::in_way(Vec2 q, double radius) const {
  for (const Passage& p : passages_) {
    const Vec2 d = q - p.centre, across{-p.axis.y, p.axis.x};
    if (std::abs(dot(d, p.axis)) <= p.half_length + 2.0 * radius &&
        std::abs(dot(d, across)) <= p.half_width + radius)
      return true;
  }
  return false;
}

bool PassageRules::sees(const Passage& p, Vec2 pos) const {
  const Vec2 u = p.axis, across{-u.y, u.x};
  const Vec2 mouth = p.centre + u * (dot(pos - p.centre, u) < 0.0 ? -p.half_length : p.half_length);
  const Vec2 to =
      closest_on_segment(pos, mouth - across * p.half_width, mouth + across * p.half_width);
  for (const WallExtent& w : walls_) {
    if (blocks(w, pos, to)) return false;
  }
  return true;
}

void PassageRules::update(double t, std::span<const Agent> agents, std::span<const Vec2> target,
                          const std::vector<bool>& active) {
  held_.assign(agents.size(), 0);
  hold_.resize(agents.size());
  queued_.resize(agents.size(), 0);
  queue_at_.resize(agents.size());
  way_.resize(agents.size() * passages_.size(), 0);
  was_held_by_.swap(held_by_);
  was_held_by_.resize(agents.size(), -1);
  held_by_.assign(agents.size(), -1);
  was_stood_by_.swap(stood_by_);
  was_stood_by_.resize(agents.size(), -1);
  stood_by_.assign(agents.size(), -1);
  stand_at_.resize(agents.size());
  round_way_.resize(agents.size() * passages_.size(), 0);
  round_to_.resize(agents.size() * passages_.size(), 0.0);
  round_next_.resize(agents.size() * passages_.size(), 0.0);
  dir_of_.assign(agents.size() * passages_.size(), 0);
  round_of_.assign(agents.size() * passages_.size(), 0);
  near_.assign(agents.size() * passages_.size(), 0);
  ahead_.assign(agents.size() * passages_.size(), 0);
  chain_way_.resize(agents.size() * chains_.size(), 0);
  counts_.resize(passages_.size());
  for (std::size_t k = 0; k < passages_.size(); ++k)
    counts_[k] = count_one(t, static_cast<int>(k), passages_[k], agents, target, active);
  for (std::size_t c = 0; c < chains_.size(); ++c) take_turns(t, static_cast<int>(c), agents);
  for (std::size_t k = 0; k < passages_.size(); ++k)
    hold_one(static_cast<int>(k), passages_[k], agents, target);
  // A figure keeps its place in a queue only while it stays queued.
  for (char& q : queued_) q = q == 2 ? 1 : 0;
}

int PassageRules::single_file(const Passage& p, std::span<const Agent> agents) const {
  if (p.owner == 0 || p.half_width >= 2.0 * avoid_radius_) return -1;
  const Vec2 mouth = p.centre - p.axis * (p.owner * p.half_length);
  const auto index = static_cast<std::size_t>(&p - passages_.data());
  int next = -1;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    if (dir_of_[i * passages_.size() + index] != p.owner) continue;
    const double s = dot(agents[i].position - p.centre, p.axis) * p.owner;
    if (s >= -p.half_length) continue;  // in the passage already
    const double d = norm(agents[i].position - mouth);
    if (d < best) {
      best = d;
      next = static_cast<int>(i);
    }
  }
  return next;
}

PassageRules::Count PassageRules::count_one(double t, int index, const Passage& p,
                                            std::span<const Agent> agents,
                                            std::span<const Vec2> target,
                                            const std::vector<bool>& active) {
  const Vec2 u = p.axis, across{-u.y, u.x};
  const double hl = p.half_length, hw = p.half_width;
  const double reach = hl + params_.approach_m;
  Count c;
  c.nearest[0] = c.nearest[1] = std::numeric_limits<double>::infinity();
  const std::size_t np = passages_.size();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const std::size_t at = i * np + static_cast<std::size_t>(index);
    signed char& known = way_[at];
    const Vec2 d = agents[i].position - p.centre;
    const double along = dot(d, u);
    const double side = std::abs(dot(d, across));
    if (!active[i] || std::abs(along) > std::max(reach, hl + params_.clear_m) ||
        side > hw + params_.approach_m) {
      known = 0;
      round_way_[at] = 0;
      continue;
    }
    // Only a figure that sees the passage from where it stands asks for
    // it: walls at any angle leave figures round a corner from a gap (past
    // it, or not there yet). One the passage holds keeps asking while it
    // walks to its place.
    const bool in_it = std::abs(along) <= hl && side <= hw + agents[i].radius;
    signed char& round = round_way_[at];
    if (!in_it && (was_held_by_[i] != index || was_stood_by_[i] == index) &&
        !sees(p, agents[i].position)) {
      known = 0;
      // Round a wall's end from the passage, its way through it: on its
      // way the figure comes round the corner into the other way's way
      // out, so while that way has the passage it waits where it is.
      if (round == 0 && t >= round_next_[at]) {
        round = way_round(p, agents[i].position, target[i], round_to_[at]);
        if (round == 0) round_next_[at] = t + 1.0;  // not near yet: asked again in a second
      }
      if (round == 0 || round == kNotThrough) continue;
      const int k = round > 0 ? 0 : 1;
      dir_of_[at] = round;
      round_of_[at] = 1;
      ahead_[at] = 1;
      ++c.want[k];
      c.nearest[k] = std::min(c.nearest[k], round_to_[at] + hl);
      continue;
    }
    round = 0;
    if (known == 0) known = way_through(p, agents[i].position, target[i]);
    if (known == kNotThrough) continue;
    const int dir = known;
    const double s = along * dir;  // < 0 before the passage, > 0 past it
    if (s > hl + params_.clear_m || s < -reach) {
      known = 0;
      continue;
    }
    const int k = dir > 0 ? 0 : 1;
    dir_of_[at] = static_cast<signed char>(dir);
    ahead_[at] = s <= hl ? 1 : 0;
    ++c.want[k];
    // Out of the far mouth, a figure no longer holds up a swap of the
    // passage: the other way, standing at that mouth, may be what it must
    // walk round.
    if (s >= -(hl + params_.close_m) && s <= hl) {
      ++c.in[k];
      near_[at] = 1;
    }
    c.nearest[k] = std::min(c.nearest[k], -s);
  }
  return c;
}

void PassageRules::take_turns(double t, int chain, std::span<const Agent> agents) {
  PassageChain& ch = chains_[static_cast<std::size_t>(chain)];
  int want[2] = {0, 0}, in[2] = {0, 0};
  double nearest[2] = {std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::infinity()};
  for (std::size_t m = 0; m < ch.members.size(); ++m) {
    const Count& c = counts_[static_cast<std::size_t>(ch.members[m])];
    for (const int way : {1, -1}) {
      const int k = idx(way * ch.orient[m]);
      want[k] += c.want[idx(way)];
      in[k] += c.in[idx(way)];
      nearest[k] = std::min(nearest[k], c.nearest[idx(way)]);
    }
  }
  if (ch.members.size() > 1) {
    // A figure that came near one of the chain's passages (and so goes on
    // through it whatever the turn) is in the chain until it asks for none
    // of them: between two, it is still on its way through, and a swap
    // then would meet it head on in the next.
    const std::size_t np = passages_.size();
    for (std::size_t i = 0; i < agents.size(); ++i) {
      signed char& way = chain_way_[i * chains_.size() + static_cast<std::size_t>(chain)];
      bool asks = false, ahead = false;
      for (std::size_t m = 0; m < ch.members.size(); ++m) {
        const std::size_t at = i * np + static_cast<std::size_t>(ch.members[m]);
        if (dir_of_[at] == 0) continue;
        asks = true;
        ahead = ahead || ahead_[at];
        if (near_[at]) way = static_cast<signed char>(dir_of_[at] * ch.orient[m]);
      }
      if (!asks) way = 0;
      // Out of the chain's last passage, it no longer holds up a swap.
      if (way != 0 && ahead) ++in[idx(way)];
    }
  }
  if (ch.owner == 0) {
    if (want[0] + want[1] > 0) ch.owner = nearest[0] <= nearest[1] ? 1 : -1;
    ch.waiting_since = -1.0;
    ch.closing = false;
  } else if (want[idx(ch.owner)] == 0) {
    ch.owner = want[idx(-ch.owner)] > 0 ? -ch.owner : 0;
    ch.waiting_since = -1.0;
    ch.closing = false;
  } else if (want[idx(-ch.owner)] > 0) {
    if (ch.waiting_since < 0.0) ch.waiting_since = t;
    if (t - ch.waiting_since >= params_.max_hold_s) ch.closing = true;
    if (ch.closing && in[idx(ch.owner)] == 0) {
      ch.owner = -ch.owner;
      ch.waiting_since = -1.0;
      ch.closing = false;
    }
  } else {
    ch.waiting_since = -1.0;
    ch.closing = false;
  }
  for (std::size_t m = 0; m < ch.members.size(); ++m) {
    Passage& p = passages_[static_cast<std::size_t>(ch.members[m])];
    p.owner = ch.owner * ch.orient[m];
  }
}

void PassageRules::hold_one(int index, const Passage& p, std::span<const Agent> agents,
                            std::span<const Vec2> target) {
  const Vec2 u = p.axis, across{-u.y, u.x};
  const double hl = p.half_length, hw = p.half_width;
  const std::size_t np = passages_.size();
  const int chain = chain_of_[static_cast<std::size_t>(index)];
  const PassageChain& ch = chains_[static_cast<std::size_t>(chain)];
  const auto member = std::find(ch.members.begin(), ch.members.end(), index) - ch.members.begin();
  const int next = single_file(p, agents);
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const std::size_t at = i * np + static_cast<std::size_t>(index);
    const int dir = dir_of_[at];
    if (dir == 0 || held_[i]) continue;
    // A figure through a passage before this one in its chain is on its
    // way through the chain: closing, it goes on, as one near the mouth.
    const bool in_chain =
        ch.members.size() > 1 && chain_way_[i * chains_.size() + static_cast<std::size_t>(chain)] ==
                                     dir * ch.orient[static_cast<std::size_t>(member)];
    if (round_of_[at]) {
      if (dir == p.owner && (!ch.closing || in_chain)) continue;
      // One already at the corner goes on: stood there, it would stand in
      // the way out it was to keep clear of.
      if (was_stood_by_[i] != index &&
          world_->path_length(agents[i].position, p.centre - u * (dir * hl)).value_or(0.0) <
              kRoundGoesOnM)
        continue;
      held_[i] = 1;
      held_by_[i] = index;
      stood_by_[i] = index;
      if (was_stood_by_[i] != index) stand_at_[i] = agents[i].position;
      hold_[i] = stand_at_[i];
      continue;
    }
    const Vec2 d = agents[i].position - p.centre;
    const double s = dot(d, u) * dir;
    if (s > hl) continue;  // through: it walks on out, whoever has the passage now
    const double side = std::abs(dot(d, across));
    const bool inside = s >= -hl && side <= hw + agents[i].radius;
    // Closing, the owner's figures already near the mouth go on: stopped in
    // a stream, touching, they could not turn out of its way.
    const bool near = s >= -(hl + params_.close_m) || in_chain;
    const bool wait = (dir != p.owner && !inside) || (dir == p.owner && ch.closing && !near);
    if (!wait) {
      // One lane: the owner's figures near the mouth stand where they are
      // and go in one at a time, nearest first; several pressing into it
      // from a wide front lock there.
      if (next < 0 || static_cast<int>(i) == next || dir != p.owner || s >= -hl ||
          norm(agents[i].position - (p.centre - u * (dir * hl))) > params_.queue_m)
        continue;
      held_[i] = 1;
      held_by_[i] = index;
      if (!queued_[i]) queue_at_[i] = agents[i].position;
      queued_[i] = 2;
      hold_[i] = queue_at_[i];
      continue;
    }
    // Beside the mouth, clear of the way out of the passage: on the
    // figure's right (figures coming out keep to their own right, the
    // other side), unless the way out turns there or the right has no
    // room (choose_side).
    held_[i] = 1;
    held_by_[i] = index;
    const int on = p.wait_side[idx(dir)] != 0 ? p.wait_side[idx(dir)]
                                              : choose_side(index, dir, agents, target);
    hold_[i] = wait_place(index, dir, on);
  }
}

signed char PassageRules::way_round(const Passage& p, Vec2 pos, Vec2 goal, double& to) const {
  if (!world_) return kNotThrough;
  const auto plus = world_->path_length(pos, p.centre + p.axis * p.half_length);
  const auto minus = world_->path_length(pos, p.centre - p.axis * p.half_length);
  if (!plus && !minus) return kNotThrough;
  const int from = !minus || (plus && *plus <= *minus) ? 1 : -1;
  to = from > 0 ? *plus : *minus;
  if (to > params_.approach_m) return 0;
  return way_through(p, pos, goal, from);
}

signed char PassageRules::way_through(const Passage& p, Vec2 pos, Vec2 goal) const {
  return way_through(p, pos, goal, dot(pos - p.centre, p.axis) < 0.0 ? -1 : 1);
}

signed char PassageRules::way_through(const Passage& p, Vec2 pos, Vec2 goal, int from) const {
  // Without a mesh, or while no way leads to the goal (a gap closed for
  // now), the goal's side of the passage in a straight line decides.
  const double way = dot(goal - p.centre, p.axis);
  const signed char straight = std::abs(way) <= p.half_length ? kNotThrough : (way > 0 ? 1 : -1);
  if (!world_) return straight;
  const Vec2 near = p.centre + p.axis * (from * p.half_length);
  const Vec2 far = p.centre - p.axis * (from * p.half_length);
  const auto direct = world_->path_length(pos, goal);
  const auto to = world_->path_length(pos, near);
  const auto on = world_->path_length(far, goal);
  if (!direct || !to || !on) return straight;
  // Through the passage when the way there and on from the far mouth is
  // no longer than the shortest way, but for the corners it cuts.
  if (*to + 2 * p.half_length + *on > *direct + 2 * p.half_width + 1.0) return kNotThrough;
  // Through and back is no way through: a figure already out of a short
  // passage whose way turns round the end of one of its walls is within
  // the corners' allowance, yet its way on from the far mouth leads back
  // across the passage.
  const auto back = world_->path(far, goal);
  if (back && crosses_middle(p, *back)) return kNotThrough;
  return static_cast<signed char>(-from);
}

Vec2 PassageRules::wait_place(int index, int dir, int side) const {
  return places_[static_cast<std::size_t>(index)][place_slot(dir, side)].at;
}

PassageRules::WaitPlace PassageRules::find_wait_place(const Passage& p, int dir, int side) const {
  const Vec2 way = p.axis * dir, right{way.y, -way.x};
  const Vec2 mouth = p.centre - way * p.half_length;
  const auto place = [&](double back, double aside) {
    return mouth - way * (back + avoid_radius_) + right * (side * (p.half_width + aside));
  };
  const Vec2 first = place(params_.wait_back_m, params_.wait_aside_m);
  if (!world_) return {first, true};
  // Where walls leave no room there (a wall across, the mesh's edge, a
  // moving obstacle's footprint): the first place nearer the passage's
  // axis, 0.5 m at a time down to 1 m aside, then the same 1.5 m farther
  // out from the wall, that a figure can stand on in sight of the mouth
  // (its middle); failing all, the nearest point of the mesh to the first.
  const double least = std::min(1.0, params_.wait_aside_m);
  for (const double back : {params_.wait_back_m, params_.wait_back_m + 1.5}) {
    for (double aside = params_.wait_aside_m; aside > least - 0.01; aside -= 0.5) {
      const Vec2 at = place(back, aside);
      bool clear = world_->on_mesh(at, 0.05);
      for (const WallExtent& w : walls_) clear = clear && !blocks(w, mouth, at);
      for (const MovingObstacle& m : world_->config().moving)
        clear = clear && NavWorld::distance_to_box(at, m.footprint) > avoid_radius_;
      if (clear) return {at, true};
    }
  }
  return {world_->nearest_on_mesh(first, 2.0 * (params_.wait_back_m + params_.wait_aside_m))
              .value_or(first),
          false};
}

int PassageRules::choose_side(int index, int dir, std::span<const Agent> agents,
                              std::span<const Vec2> target) {
  Passage& p = passages_[static_cast<std::size_t>(index)];
  // The other way's figures come out toward their goals: where the walls
  // turn their way out to this way's right (a maze), waiting there would
  // stand in it. The place on the left is taken instead when it is in
  // sight of the mouth on this side, and the other way's path to its goal
  // from the right place is shorter than from the left one by over
  // kTurnMargin (a real turn, not the noise of the mesh). Last, a side
  // with no clear place gives way to one with a clear place (below).
  constexpr double kTurnMargin = 2.0;
  if (!world_) return 1;
  int other = -1;
  for (std::size_t i = 0; i < agents.size() && other < 0; ++i) {
    if (dir_of_[i * passages_.size() + static_cast<std::size_t>(index)] == -dir)
      other = static_cast<int>(i);
  }
  // A side with no clear place (its place snapped to the mesh's edge, as
  // where the passage lies near the scene's edge: there its crowd would
  // stand round the mouth) gives way to one with a clear place.
  const auto& places = places_[static_cast<std::size_t>(index)];
  const auto clearer = [&](int side) {
    return !places[place_slot(dir, side)].clear && places[place_slot(dir, -side)].clear ? -side
                                                                                        : side;
  };
  if (other < 0) return clearer(1);  // decided once the other way is there
  const Vec2 goal = target[static_cast<std::size_t>(other)];
  const Vec2 right = wait_place(index, dir, 1), left = wait_place(index, dir, -1);
  const Vec2 mouth = p.centre - p.axis * (dir * p.half_length);
  int side = 1;
  const auto from_left = world_->path_length(left, goal);
  const auto from_right = world_->path_length(right, goal);
  bool left_in_sight = world_->on_mesh(left, 0.05);
  for (const WallExtent& w : walls_) left_in_sight = left_in_sight && !blocks(w, mouth, left);
  if (left_in_sight && from_left && (!from_right || *from_right + kTurnMargin < *from_left))
    side = -1;
  side = clearer(side);
  p.wait_side[idx(dir)] = side;
  return side;
}

}  // namespace animrt::herd
