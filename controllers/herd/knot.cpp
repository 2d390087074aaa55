#include "animrt/controllers/herd/knot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace animrt::herd {

KnotRules::KnotRules(std::size_t agents, KnotParams params)
    : params_(params), anchor_(agents), since_(agents, 0.0), until_(agents, -1.0), point_(agents) {
  stalled_.reserve(agents);
  parent_.reserve(agents);
  members_.reserve(agents);
}

void KnotRules::update(double t, std::span<const Agent> agents, std::span<const Vec2> target,
                       std::span<const char> travelling) {
  if (params_.still_s <= 0.0) return;
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const Vec2 p = agents[i].position;
    if (until_[i] >= 0.0 && t >= until_[i]) until_[i] = -1.0;  // it walks on
    if (!travelling[i] || until_[i] >= 0.0 || norm(p - anchor_[i]) > params_.progress_m) {
      anchor_[i] = p;
      since_[i] = t;
    }
  }
  if (t - last_check_ < params_.check_s) return;
  last_check_ = t;
  find_knots(t, agents, target);
}

int KnotRules::root(int i) {
  auto& p = parent_;
  while (p[static_cast<std::size_t>(i)] != i) {
    p[static_cast<std::size_t>(i)] = p[static_cast<std::size_t>(p[static_cast<std::size_t>(i)])];
    i = p[static_cast<std::size_t>(i)];
  }
  return i;
}

void KnotRules::find_knots(double t, std::span<const Agent> agents, std::span<const Vec2> target) {
  stalled_.clear();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    if (until_[i] < 0.0 && t - since_[i] >= params_.still_s)
      stalled_.push_back(static_cast<int>(i));
  }
  const int s = static_cast<int>(stalled_.size());
  if (s < 2) return;
  parent_.resize(stalled_.size());
  std::iota(parent_.begin(), parent_.end(), 0);
  for (int a = 0; a < s; ++a) {
    const Agent& x = agents[static_cast<std::size_t>(stalled_[static_cast<std::size_t>(a)])];
    for (int b = a + 1; b < s; ++b) {
      const Agent& y = agents[static_cast<std::size_t>(stalled_[static_cast<std::size_t>(b)])];
      if (norm(x.position - y.position) < x.radius + y.radius + params_.link_m) {
        parent_[static_cast<std::size_t>(root(a))] = root(b);
      }
    }
  }
  for (int a = 0; a < s; ++a) {
    if (root(a) != a) continue;
    members_.clear();
    for (int b = 0; b < s; ++b) {
      if (root(b) == a) members_.push_back(stalled_[static_cast<std::size_t>(b)]);
    }
    if (members_.size() >= 2) resolve(t, members_, agents, target);
  }
}

void KnotRules::resolve(double t, std::span<const int> knot, std::span<const Agent> agents,
                        std::span<const Vec2> target) {
  ++knots_;
  // Who yields: with two or more ways (groups) in the knot, the group with
  // the fewest figures in it (the fewest to move; a tie goes to the lower
  // or the higher group by turns); with one way, every figure but the one
  // nearest its goal.
  const auto group = [&](int i) { return agents[static_cast<std::size_t>(i)].group; };
  int yield_group = group(knot[0]), fewest = std::numeric_limits<int>::max();
  bool mixed = false;
  for (const int i : knot) {
    mixed = mixed || group(i) != group(knot[0]);
    const int g = group(i);
    const auto n = static_cast<int>(
        std::count_if(knot.begin(), knot.end(), [&](int j) { return group(j) == g; }));
    const bool lower_wins = knots_ % 2 == 1;
    if (n < fewest || (n == fewest && (lower_wins ? g < yield_group : g > yield_group))) {
      fewest = n;
      yield_group = g;
    }
  }
  int goer = -1;
  if (!mixed) {
    double best = std::numeric_limits<double>::infinity();
    for (const int i : knot) {
      const auto k = static_cast<std::size_t>(i);
      const double d = norm(target[k] - agents[k].position);
      if (d < best) {
        best = d;
        goer = i;
      }
    }
  }
  const auto yields = [&](int i) { return mixed ? group(i) == yield_group : i != goer; };
  Vec2 centre;  // of the figures that go on
  int going = 0;
  for (const int i : knot) {
    if (yields(i)) continue;
    centre += agents[static_cast<std::size_t>(i)].position;
    ++going;
    since_[static_cast<std::size_t>(i)] = t;  // they go on: not a knot again at once
  }
  centre = centre / static_cast<double>(std::max(going, 1));
  for (const int i : knot) {
    if (!yields(i)) continue;
    const auto k = static_cast<std::size_t>(i);
    const Vec2 p = agents[k].position;
    Vec2 away = p - centre;
    if (norm(away) < 1e-6) away = p - target[k];  // back along its way
    point_[k] = p + normalized(away) * params_.back_off_m;
    until_[k] = t + params_.back_off_s;
  }
}

}  // namespace animrt::herd
