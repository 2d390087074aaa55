#pragma once
// A walking figure in the herd: it cannot slide sideways; it walks forward
// at a speed and turns at a rate its gait can do, and turns on the spot
// (speed 0) only where its gait can (WalkResponse::spot_turn).
// steer_figure() turns a group's desired ground velocity into that command,
// and walk_figure() moves the agent by what the gait achieves.

#include <string>

#include "animrt/controllers/gait/walk_response.hpp"
#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

struct Figure {
  std::string name;
  double radius_m = 0.25;
  WalkResponse walk;
};

// The radius of the tightest circle a figure that turns only while it
// walks can walk (its slowest walk at that walk's fastest turn); 0 for one
// that turns on the spot or not at all.
double turning_radius(const Figure& figure);

// Seconds in which a figure means to close its heading error (the turn it
// asks for is error / this, within its limits).
inline constexpr double kHeadingTimeConstant_s = 0.3;

// The command given to `figure` for walking `agent` toward `desired` (m/s on
// the ground) over the next `dt`: forward speed from the part of `desired`
// along the heading, a turn toward it, both within what the gait can walk
// and its acceleration, as command_for() of the walk response chooses; for
// a velocity behind it, a turn on the spot when the gait has one.
MotionCommand steer_figure(const Figure& figure, const Agent& agent, Vec2 desired, double dt);

// The command for a figure the contact guard stopped, `toward` the sum of
// unit vectors to the figures it would have stepped into: a turn on the
// spot (when its gait has one) toward `desired` less the part that closes
// on them, or to the right of them when nothing else is left. Standing
// nose to a neighbour with its way ahead, it would otherwise never leave.
MotionCommand turn_clear(const Figure& figure, const Agent& agent, Vec2 desired, Vec2 toward);

// Moves `agent` for `dt` by what `figure` achieves under `command`:
// heading and position integrated at the midpoint heading.
void walk_figure(const Figure& figure, const MotionCommand& command, double dt, Agent& agent);

}  // namespace animrt::herd
