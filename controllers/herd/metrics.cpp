#include "animrt/controllers/herd/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace animrt::herd {
namespace {

constexpr double kStuckWindow_s = 5.0;
// A figure walks, for the order, when faster than this part of its top speed
// (or than kMovingFloor_mps when its top speed is unknown); a flock stands
// when its mean speed is under this part of its leader's.
constexpr double kMovingFraction = 0.1;
constexpr double kMovingFloor_mps = 0.005;
constexpr double kStandingFraction = 0.1;

}  // namespace

MetricsRecorder::MetricsRecorder(std::vector<GroupInfo> groups, std::span<const Agent> start,
                                 double settle_s)
    : groups_(std::move(groups)),
      group_of_(start.size(), -1),
      tracks_(start.size()),
      sums_(groups_.size()),
      max_speed_(start.size(), 0.0),
      settle_s_(settle_s),
      order_(start.size()) {
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    for (int i : groups_[g].members) group_of_[static_cast<std::size_t>(i)] = static_cast<int>(g);
  }
  for (std::size_t i = 0; i < start.size(); ++i) {
    tracks_[i].start = tracks_[i].last = tracks_[i].anchor = start[i].position;
  }
}

void MetricsRecorder::sample(double t, std::span<const Agent> agents,
                             std::span<const std::optional<Vec2>> leaders,
                             std::span<const char> arrived, std::span<const double> max_speed) {
  const std::size_t n = agents.size();
  ++steps_;
  // Speeds and directions are the figures' own motion since the last
  // sample, not the speed their gaits were asked for: a figure pressed
  // against a wall or stopped by the contact guard walks nowhere.
  const double since = t - last_t_;
  last_t_ = t;
  const auto motion = [&](std::size_t i) {
    return since > 0.0 ? (agents[i].position - tracks_[i].last) / since : Vec2{};
  };
  double max_radius = 0.0;
  for (const Agent& a : agents) max_radius = std::max(max_radius, a.radius);

  // Pairs closer than the sum of radii, by a sweep over x; the sweep also
  // reaches as far as the closest pair found so far, so the scene's minimum
  // pair distance is exact even for figures far apart.
  std::iota(order_.begin(), order_.end(), 0);
  std::sort(order_.begin(), order_.end(), [&](int a, int b) {
    return agents[static_cast<std::size_t>(a)].position.x <
           agents[static_cast<std::size_t>(b)].position.x;
  });
  const double contact_reach = 2 * max_radius;
  double step_min = 1e300;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = static_cast<std::size_t>(order_[k]);
    const Agent& a = agents[i];
    for (std::size_t m = k + 1; m < n; ++m) {
      const std::size_t j = static_cast<std::size_t>(order_[m]);
      const Agent& b = agents[j];
      const double dx = b.position.x - a.position.x;
      if (dx > contact_reach && dx > step_min) break;
      const double d = norm(b.position - a.position);
      const double clearance = d - (a.radius + b.radius);
      min_clearance_ = std::min(min_clearance_, clearance);
      step_min = std::min(step_min, d);
      if (dx > contact_reach) continue;  // beyond contact: only the scene's minimum
      const int gi = group_of_[i], gj = group_of_[j];
      for (int g : {gi, gj}) {
        if (g >= 0) {
          double& mp = sums_[static_cast<std::size_t>(g)].min_pair;
          mp = std::min(mp, d);
        }
      }
      if (clearance < 0) {
        ++collisions_;
        if (gi >= 0) ++sums_[static_cast<std::size_t>(gi)].collisions;
        if (gj >= 0 && gj != gi) ++sums_[static_cast<std::size_t>(gj)].collisions;
      }
    }
  }
  min_pair_ = std::min(min_pair_, step_min);
  // Nearest neighbour within the own group: scan both ways in x order until
  // the x gap alone exceeds the best distance found.
  std::vector<double> nearest(n, 1e300);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = static_cast<std::size_t>(order_[k]);
    const Agent& a = agents[i];
    double& best = nearest[i];
    for (std::size_t m = k + 1; m < n; ++m) {
      const Agent& b = agents[static_cast<std::size_t>(order_[m])];
      if (b.position.x - a.position.x > best) break;
      if (group_of_[static_cast<std::size_t>(order_[m])] == group_of_[i])
        best = std::min(best, norm(b.position - a.position));
    }
    for (std::size_t m = k; m-- > 0;) {
      const Agent& b = agents[static_cast<std::size_t>(order_[m])];
      if (a.position.x - b.position.x > best) break;
      if (group_of_[static_cast<std::size_t>(order_[m])] == group_of_[i])
        best = std::min(best, norm(b.position - a.position));
    }
  }

  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const GroupInfo& info = groups_[g];
    GroupSums& s = sums_[g];
    if (info.members.empty()) continue;
    Vec2 sum_v, centre;
    double sum_speed = 0.0, all_speed = 0.0, nn = 0.0;
    int nn_count = 0, moving = 0;
    for (int i : info.members) {
      const Agent& a = agents[static_cast<std::size_t>(i)];
      const double top = static_cast<std::size_t>(i) < max_speed.size()
                             ? max_speed[static_cast<std::size_t>(i)]
                             : 0.0;
      const double floor = top > 0 ? kMovingFraction * top : kMovingFloor_mps;
      const Vec2 v = motion(static_cast<std::size_t>(i));
      const double speed = norm(v);
      all_speed += speed;
      if (speed > floor) {
        sum_v += v;
        sum_speed += speed;
        ++moving;
      }
      centre += a.position;
      if (nearest[static_cast<std::size_t>(i)] < 1e299) {
        nn += nearest[static_cast<std::size_t>(i)];
        ++nn_count;
      }
    }
    centre = centre / static_cast<double>(info.members.size());
    if (nn_count > 0) {
      s.nn_sum += nn / nn_count;
      ++s.nn_steps;
    }
    if (t >= settle_s_) {
      s.speed_sum += all_speed / static_cast<double>(info.members.size());
      ++s.speed_steps;
    }
    if (t >= settle_s_ && moving >= 2) {
      const double order = norm(sum_v) / sum_speed;
      s.order_sum += order;
      s.order_min = std::min(s.order_min, order);
      ++s.order_steps;
    }
    if (g < leaders.size() && leaders[g]) {
      // The leader's speed from its positions, over the steps the flock's
      // speed is averaged over.
      if (s.leader_last && t >= settle_s_ && t > s.leader_last_t) {
        s.leader_walked += norm(*leaders[g] - *s.leader_last);
        s.leader_time += t - s.leader_last_t;
      }
      s.leader_last = leaders[g];
      s.leader_last_t = t;
      const double d = norm(centre - *leaders[g]);
      s.leader_sum += d;
      s.leader_max = std::max(s.leader_max, d);
      ++s.leader_steps;
    }
  }

  for (std::size_t i = 0; i < n; ++i) {
    AgentTrack& tr = tracks_[i];
    const Agent& a = agents[i];
    tr.walked += norm(a.position - tr.last);
    tr.last = a.position;
    if (i < max_speed.size()) max_speed_[i] = max_speed[i];
    const bool at_goal = i < arrived.size() && arrived[i] != 0;
    if (at_goal && tr.arrived_at < 0) {
      tr.arrived_at = t;
      tr.walked_at_arrival = tr.walked;
    }
    if (tr.arrived_at < 0 && !at_goal) {
      if (norm(a.position - tr.anchor) >= a.radius) {
        tr.anchor = a.position;
        tr.anchor_t = t;
      } else if (t - tr.anchor_t > kStuckWindow_s) {
        tr.stuck = true;
      }
    }
  }
}

HerdMetrics MetricsRecorder::finish() const {
  HerdMetrics m;
  m.duration_s = last_t_;
  m.steps = steps_;
  m.collisions = collisions_;
  m.contact_stops = contact_stops_;
  m.knots = knots_;
  m.has_pair = min_pair_ < 1e299;
  m.min_pair_distance_m = m.has_pair ? min_pair_ : 0.0;
  m.min_clearance_m = m.has_pair ? min_clearance_ : 0.0;
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const GroupInfo& info = groups_[g];
    const GroupSums& s = sums_[g];
    GroupMetrics gm;
    gm.name = info.name;
    gm.kind = info.kind;
    gm.agents = static_cast<int>(info.members.size());
    gm.collisions = s.collisions;
    gm.has_pair = s.min_pair < 1e299;
    gm.min_pair_distance_m = gm.has_pair ? s.min_pair : 0.0;
    gm.order_steps = s.order_steps;
    if (s.order_steps > 0) {
      gm.order_mean = s.order_sum / static_cast<double>(s.order_steps);
      gm.order_min = s.order_min;
    }
    if (s.speed_steps > 0) gm.speed_mean_mps = s.speed_sum / static_cast<double>(s.speed_steps);
    if (s.leader_time > 0) {
      gm.leader_speed_mean_mps = s.leader_walked / s.leader_time;
      gm.standing = gm.speed_mean_mps < kStandingFraction * gm.leader_speed_mean_mps;
    }
    gm.has_neighbour = s.nn_steps > 0;
    if (s.nn_steps > 0) gm.nearest_neighbour_mean_m = s.nn_sum / static_cast<double>(s.nn_steps);
    if (s.leader_steps > 0) {
      gm.leader_distance_mean_m = s.leader_sum / static_cast<double>(s.leader_steps);
      gm.leader_distance_max_m = s.leader_max;
    }
    if (info.target) {
      gm.arrivals = 0;
      double time_sum = 0.0, path_sum = 0.0;
      for (int i : info.members) {
        const AgentTrack& tr = tracks_[static_cast<std::size_t>(i)];
        if (tr.arrived_at < 0) {
          if (tr.stuck) ++gm.stuck;  // one that waited, then arrived, was not stuck
          continue;
        }
        ++gm.arrivals;
        time_sum += tr.arrived_at;
        gm.time_to_goal_max_s = std::max(gm.time_to_goal_max_s, tr.arrived_at);
        const double straight = norm(*info.target - tr.start);
        if (straight > 1e-9) {
          const double path = tr.walked_at_arrival / straight;
          path_sum += path;
          gm.path_ratio_max = std::max(gm.path_ratio_max, path);
          const double v = max_speed_[static_cast<std::size_t>(i)];
          if (v > 0)
            gm.time_ratio_max = std::max(gm.time_ratio_max, tr.arrived_at / (straight / v));
        }
      }
      if (gm.arrivals > 0) {
        gm.time_to_goal_mean_s = time_sum / gm.arrivals;
        gm.path_ratio_mean = path_sum / gm.arrivals;
      }
    }
    m.groups.push_back(gm);
  }
  return m;
}

}  // namespace animrt::herd
