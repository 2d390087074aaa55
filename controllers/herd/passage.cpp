#include "animrt/controllers/herd/passage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace animrt::herd {
namespace {

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

// The passage between two intervals on one axis, overlapping on the other:
// gap [lo, hi] across, overlap [a, b] along.
Passage make_passage(double lo, double hi, double a, double b, bool across_is_y) {
  Passage p;
  const double mid = (lo + hi) / 2, along = (a + b) / 2;
  p.centre = across_is_y ? Vec2{along, mid} : Vec2{mid, along};
  p.axis = across_is_y ? Vec2{1, 0} : Vec2{0, 1};
  p.half_width = (hi - lo) / 2;
  p.half_length = (b - a) / 2;
  return p;
}

}  // namespace

std::vector<Passage> find_passages(std::span<const Box> walls, double max_width) {
  std::vector<Passage> out;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    Rect a;
    if (!aligned_extent(walls[i], a)) continue;
    for (std::size_t j = i + 1; j < walls.size(); ++j) {
      Rect b;
      if (!aligned_extent(walls[j], b)) continue;
      const double ox0 = std::max(a.xmin, b.xmin), ox1 = std::min(a.xmax, b.xmax);
      const double oy0 = std::max(a.ymin, b.ymin), oy1 = std::min(a.ymax, b.ymax);
      if (ox1 > ox0) {  // one above the other: the gap is in y
        const double lo = std::min(a.ymax, b.ymax), hi = std::max(a.ymin, b.ymin);
        if (hi > lo && hi - lo < max_width) out.push_back(make_passage(lo, hi, ox0, ox1, true));
      } else if (oy1 > oy0) {  // side by side: the gap is in x
        const double lo = std::min(a.xmax, b.xmax), hi = std::max(a.xmin, b.xmin);
        if (hi > lo && hi - lo < max_width) out.push_back(make_passage(lo, hi, oy0, oy1, false));
      }
    }
  }
  return out;
}

PassageRules::PassageRules(std::span<const Box> walls, double avoid_radius, PassageParams params)
    : passages_(find_passages(walls, params.max_width_radii * avoid_radius)),
      avoid_radius_(avoid_radius),
      params_(params) {}

void PassageRules::update(double t, std::span<const Agent> agents, std::span<const Vec2> target,
                          const std::vector<bool>& active) {
  held_.assign(agents.size(), 0);
  hold_.resize(agents.size());
  queued_.resize(agents.size(), 0);
  queue_at_.resize(agents.size());
  for (Passage& p : passages_) update_one(t, p, agents, target, active);
  // A figure keeps its place in a queue only while it stays queued.
  for (char& q : queued_) q = q == 2 ? 1 : 0;
}

int PassageRules::single_file(const Passage& p, std::span<const Agent> agents) const {
  if (p.owner == 0 || p.half_width >= 2.0 * avoid_radius_) return -1;
  const Vec2 mouth = p.centre - p.axis * (p.owner * p.half_length);
  int next = -1;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    if (dir_of_[i] != p.owner) continue;
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

void PassageRules::update_one(double t, Passage& p, std::span<const Agent> agents,
                              std::span<const Vec2> target, const std::vector<bool>& active) {
  const Vec2 u = p.axis, across{-u.y, u.x};
  const double hl = p.half_length, hw = p.half_width;
  const double reach = hl + params_.approach_m;
  int want[2] = {0, 0}, in[2] = {0, 0};  // asking for the passage, and near its mouth
  double nearest[2] = {std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::infinity()};
  std::vector<signed char>& dir_of = dir_of_;
  dir_of.assign(agents.size(), 0);
  for (std::size_t i = 0; i < agents.size(); ++i) {
    if (!active[i]) continue;
    const Vec2 d = agents[i].position - p.centre;
    const double way = dot(target[i] - p.centre, u);
    if (std::abs(way) <= hl) continue;  // its goal is in the passage itself
    const int dir = way > 0 ? 1 : -1;
    const double s = dot(d, u) * dir;  // < 0 before the passage, > 0 past it
    const double side = std::abs(dot(d, across));
    if (s > hl + params_.clear_m || s < -reach || side > hw + params_.approach_m) continue;
    const int k = dir > 0 ? 0 : 1;
    dir_of[i] = static_cast<signed char>(dir);
    ++want[k];
    if (s >= -(hl + params_.close_m)) ++in[k];
    nearest[k] = std::min(nearest[k], -s);
  }
  const auto idx = [](int dir) { return dir > 0 ? 0 : 1; };
  if (p.owner == 0) {
    if (want[0] + want[1] > 0) p.owner = nearest[0] <= nearest[1] ? 1 : -1;
    p.waiting_since = -1.0;
    p.closing = false;
  } else if (want[idx(p.owner)] == 0) {
    p.owner = want[idx(-p.owner)] > 0 ? -p.owner : 0;
    p.waiting_since = -1.0;
    p.closing = false;
  } else if (want[idx(-p.owner)] > 0) {
    if (p.waiting_since < 0.0) p.waiting_since = t;
    if (t - p.waiting_since >= params_.max_hold_s) p.closing = true;
    if (p.closing && in[idx(p.owner)] == 0) {
      p.owner = -p.owner;
      p.waiting_since = -1.0;
      p.closing = false;
    }
  } else {
    p.waiting_since = -1.0;
    p.closing = false;
  }
  const int next = single_file(p, agents);
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const int dir = dir_of[i];
    if (dir == 0 || held_[i]) continue;
    const Vec2 d = agents[i].position - p.centre;
    const double s = dot(d, u) * dir;
    const double side = std::abs(dot(d, across));
    const bool inside = s >= -hl && side <= hw + agents[i].radius;
    // Closing, the owner's figures already near the mouth go on: stopped in
    // a stream, touching, they could not turn out of its way.
    const bool near = s >= -(hl + params_.close_m);
    const bool wait = (dir != p.owner && !inside) || (dir == p.owner && p.closing && !near);
    if (!wait) {
      // One lane: the owner's figures near the mouth stand where they are
      // and go in one at a time, nearest first; several pressing into it
      // from a wide front lock there.
      if (next < 0 || static_cast<int>(i) == next || dir != p.owner || s >= -hl ||
          norm(agents[i].position - (p.centre - u * (dir * hl))) > params_.queue_m)
        continue;
      held_[i] = 1;
      if (!queued_[i]) queue_at_[i] = agents[i].position;
      queued_[i] = 2;
      hold_[i] = queue_at_[i];
      continue;
    }
    // Beside the mouth on the figure's right, clear of the way out of the
    // passage (figures coming out keep to their own right, the other side).
    const Vec2 way = u * dir, right{way.y, -way.x};
    held_[i] = 1;
    hold_[i] = p.centre - way * (hl + 3.0 + avoid_radius_) + right * (hw + 2.5);
  }
}

}  // namespace animrt::herd
