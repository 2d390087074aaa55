#include "animrt/controllers/herd/figure.hpp"

#include <algorithm>
#include <cmath>

namespace animrt::herd {

MotionCommand steer_figure(const Figure& figure, const Agent& agent, Vec2 desired, double dt) {
  const WalkResponse& walk = figure.walk;
  const double wanted = norm(desired);
  MotionCommand want;
  const Vec2 h = heading_vector(agent.heading);
  const double error = std::atan2(cross(h, desired), dot(h, desired));
  const double cos_error = std::cos(error);
  // A figure that cannot turn only walks toward a velocity ahead of it:
  // walking on could never bring it round to one behind.
  const bool reachable_way = walk.max_turn(walk.min_speed()) > 0.0 || cos_error > 0.0;
  const bool wants_walk = wanted >= 0.5 * walk.min_speed() && wanted > 1e-9;
  // A figure that can turn on the spot turns there toward a velocity behind
  // it, once it can stop this step, rather than walk a circle into whatever
  // stands before it (a wall, a neighbour).
  const double spot = walk.spot_turn();
  if (wants_walk && spot > 0.0 && cos_error < 0.0 &&
      agent.speed - walk.max_acceleration() * dt < walk.min_speed()) {
    return {0.0, std::clamp(error / kHeadingTimeConstant_s, -spot, spot)};
  }
  if (wants_walk && reachable_way) {
    // Walk on at no less than the slowest gait while turning toward a
    // velocity behind the figure: a gait turns only while it walks.
    want.speed_m_s =
        std::clamp(wanted * std::max(cos_error, 0.0), walk.min_speed(), walk.max_speed());
    const double max_turn = walk.max_turn(want.speed_m_s);
    want.turn_rad_s = std::clamp(error / kHeadingTimeConstant_s, -max_turn, max_turn);
  }
  // The gait ramps its speed at its acceleration limit; ask for no more
  // than it can reach this step so the herd's figure and the real one agree.
  const double dv = walk.max_acceleration() * dt;
  const double reachable = std::clamp(want.speed_m_s, agent.speed - dv, agent.speed + dv);
  if (want.speed_m_s > 0.0 && reachable < walk.min_speed()) {
    want.speed_m_s = walk.min_speed();  // starting from standing: the gait's slowest walk
  } else if (want.speed_m_s == 0.0 && reachable < walk.min_speed()) {
    // Stopping: below the slowest walk the gait stands (it blends to
    // standing over a stride), where walking on at the slowest speed would
    // come closer to the ramp and never stop.
    return walk.command_for({0.0, 0.0});
  } else {
    want.speed_m_s = std::max(reachable, 0.0);
  }
  if (want.speed_m_s == 0.0) want.turn_rad_s = 0.0;
  return walk.command_for(want);
}

double turning_radius(const Figure& figure) {
  const WalkResponse& walk = figure.walk;
  const double turn = walk.max_turn(walk.min_speed());
  return walk.spot_turn() > 0.0 || !(turn > 0.0) ? 0.0 : walk.min_speed() / turn;
}

MotionCommand turn_clear(const Figure& figure, const Agent& agent, Vec2 desired, Vec2 toward) {
  const double spot = figure.walk.spot_turn();
  if (!(spot > 0.0) || norm2(toward) <= 0.0 || norm2(desired) <= 0.0) return {};
  const Vec2 n = normalized(toward);
  Vec2 way = desired;
  const double closing = dot(way, n);
  if (closing > 0.0) way -= n * closing;
  if (norm(way) < 0.1 * norm(desired)) way = Vec2{n.y, -n.x};
  const Vec2 h = heading_vector(agent.heading);
  const double error = std::atan2(cross(h, way), dot(h, way));
  return {0.0, std::clamp(error / kHeadingTimeConstant_s, -spot, spot)};
}

void walk_figure(const Figure& figure, const MotionCommand& command, double dt, Agent& agent) {
  const MotionCommand done = figure.walk.achieved(command);
  const double mid = agent.heading + 0.5 * done.turn_rad_s * dt;
  agent.position += heading_vector(mid) * (done.speed_m_s * dt);
  agent.heading = std::remainder(agent.heading + done.turn_rad_s * dt, 2.0 * M_PI);
  agent.speed = done.speed_m_s;
  agent.turn = done.turn_rad_s;
}

}  // namespace animrt::herd
