#pragma once
// Knots: crowd members that stand or mill in one small region, none of them
// making progress toward its goal, each held by the others (figures of two
// ways nose to nose in a gap no passage rule covers, or a front pressing
// into a mouth). Every plan there waits for a neighbour to move first. The
// crowd notices such a knot and lets one side yield: its figures back off
// out of the knot for a while, so the others can pass, then walk on. The
// decision is made per knot from the figures in it (no central schedule)
// and is the same for the same run.

#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

struct KnotParams {
  double still_s = 30.0;     // a member that has not moved progress_m for this long is stalled
  double progress_m = 0.3;   // (0 still_s: no knots are looked for)
  double link_m = 0.4;       // stalled members this close (surface to surface) form one knot
  double back_off_m = 1.5;   // how far a yielding member backs off
  double back_off_s = 20.0;  // and for how long, before it walks on
  double check_s = 1.0;      // how often knots are looked for
};

class KnotRules {
 public:
  KnotRules(std::size_t agents, KnotParams params);

  // `travelling[i]`: member i walks toward its goal or its slot at the
  // gathering on its own (has not arrived, is not waiting by a rule). Backs
  // off the yielding side of every new knot.
  void update(double t, std::span<const Agent> agents, std::span<const Vec2> target,
              std::span<const char> travelling);
  bool backing_off(int i) const { return until_[static_cast<std::size_t>(i)] >= 0.0; }
  Vec2 back_off_point(int i) const { return point_[static_cast<std::size_t>(i)]; }
  long knots() const { return knots_; }

 private:
  void find_knots(double t, std::span<const Agent> agents, std::span<const Vec2> target);
  int root(int i);
  void resolve(double t, std::span<const int> knot, std::span<const Agent> agents,
               std::span<const Vec2> target);

  KnotParams params_;
  std::vector<Vec2> anchor_;  // where each member was when it last made progress
  std::vector<double> since_;
  std::vector<double> until_;  // when a backing-off member walks on (-1: it does not back off)
  std::vector<Vec2> point_;    // where it backs off to
  std::vector<int> stalled_;   // scratch
  std::vector<int> parent_;    // union-find over stalled_
  std::vector<int> members_;   // scratch: one knot
  double last_check_ = -1e300;
  long knots_ = 0;
};

}  // namespace animrt::herd
