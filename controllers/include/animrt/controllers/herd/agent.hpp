#pragma once
// What every part of the herd shares: the ground plane, the agents on it,
// and the seam between a group's steering (flock, crowd) and the walking
// figures that carry it out.
//
// The ground is the x-y plane, metres; headings are radians from +x,
// counter-clockwise positive (a positive turn rate turns left), as in
// MotionCommand.

#include <cmath>
#include <span>

namespace animrt::herd {

struct Vec2 {
  double x = 0.0;
  double y = 0.0;

  Vec2& operator+=(Vec2 o) {
    x += o.x;
    y += o.y;
    return *this;
  }
  Vec2& operator-=(Vec2 o) {
    x -= o.x;
    y -= o.y;
    return *this;
  }
  Vec2& operator*=(double k) {
    x *= k;
    y *= k;
    return *this;
  }
  friend Vec2 operator+(Vec2 a, Vec2 b) { return a += b; }
  friend Vec2 operator-(Vec2 a, Vec2 b) { return a -= b; }
  friend Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
  friend Vec2 operator*(Vec2 a, double k) { return a *= k; }
  friend Vec2 operator*(double k, Vec2 a) { return a *= k; }
  friend Vec2 operator/(Vec2 a, double k) { return a *= 1.0 / k; }
  friend bool operator==(Vec2 a, Vec2 b) = default;
};

inline double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
inline double norm(Vec2 a) { return std::hypot(a.x, a.y); }
inline double norm2(Vec2 a) { return dot(a, a); }
// a / |a|, or {0, 0} for the zero vector.
inline Vec2 normalized(Vec2 a) {
  const double n = norm(a);
  return n > 0.0 ? a / n : Vec2{};
}
inline Vec2 heading_vector(double heading) { return {std::cos(heading), std::sin(heading)}; }

// An axis-aligned rectangle: [xmin, xmax] x [ymin, ymax].
struct Rect {
  double xmin = 0.0, ymin = 0.0, xmax = 0.0, ymax = 0.0;
  bool contains(Vec2 p) const { return p.x >= xmin && p.x <= xmax && p.y >= ymin && p.y <= ymax; }
  Vec2 center() const { return {(xmin + xmax) / 2, (ymin + ymax) / 2}; }
};

// A box on the ground (a wall, an obstacle's footprint): centre, full size
// along its own x and y, and its yaw.
struct Box {
  Vec2 center;
  Vec2 size;
  double yaw_rad = 0.0;
};

// One walking figure as the herd sees it. The herd owns the array of all
// agents (every group); steering reads it and never writes it.
struct Agent {
  Vec2 position;
  double heading = 0.0;  // rad
  double speed = 0.0;    // m/s forward, as the figure walks it
  double turn = 0.0;     // rad/s, as the figure walks it
  double radius = 0.25;  // m, the figure's footprint
  int group = 0;         // index of its group in the scene

  Vec2 velocity() const { return heading_vector(heading) * speed; }
};

// A group's steering: flocks and crowds implement it. Each step the herd
// calls steer() on every group with the whole herd as it stands, then turns
// each agent's desired ground velocity into a speed and turn command within
// its figure's limits and moves the agent by what its gait achieves.
class GroupSteering {
 public:
  virtual ~GroupSteering() = default;

  // Indices (into the herd's agent array) of this group's agents, fixed
  // after construction.
  virtual std::span<const int> members() const = 0;

  // Writes the desired ground velocity (m/s) of each member i into
  // desired[i]; `agents` and `desired` are indexed alike (every agent of the
  // herd). Entries of other groups' agents are left alone. `t` is the time
  // at the start of the step, `dt` its length (s).
  virtual void steer(double t, double dt, std::span<const Agent> agents,
                     std::span<Vec2> desired) = 0;
};

}  // namespace animrt::herd
