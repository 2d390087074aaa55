#pragma once
// Right of way at narrow passages: where two walls leave a gap too narrow
// for two streams to pass each other, the gap is used one way at a time.
// Each passage decides for itself (no central schedule): the first figure
// to come near takes it for its direction; figures the other way wait
// beside the mouth, clear of the way out; once the other way has waited
// max_hold_s the passage admits no new figures of the owning direction,
// and when the last of them is through, ownership swaps.

#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

struct PassageParams {
  // Gaps narrower than this many avoidance radii are passages (two
  // figures side by side need four, and room to pass them two more).
  double max_width_radii = 6.5;
  double approach_m = 6.0;  // figures this far from a mouth ask for the passage
  // Figures this near a mouth go on through when their way closes, and
  // every figure uses the passage until clear_m out of the far mouth.
  double close_m = 2.5;
  double clear_m = 1.5;
  double max_hold_s = 60.0;  // the other way waits at most this long for a turn
  // At a passage one figure wide, the owner's figures this near its mouth
  // queue there and go in one at a time.
  double queue_m = 1.5;
};

struct Passage {
  Vec2 centre;
  Vec2 axis;  // through the passage (unit)
  double half_width = 0.0;
  double half_length = 0.0;
  int owner = 0;                // +1: along axis, -1: against it, 0: free
  double waiting_since = -1.0;  // when the other way began to wait, or -1
  bool closing = false;         // the owner admits no one new
};

// Gaps between two axis-aligned walls, narrower than max_width, whose
// facing sides overlap.
std::vector<Passage> find_passages(std::span<const Box> walls, double max_width);

class PassageRules {
 public:
  PassageRules(std::span<const Box> walls, double avoid_radius, PassageParams params = {});

  // Decides, for every active agent walking to target[i], whether it must
  // wait, and where (hold_point).
  void update(double t, std::span<const Agent> agents, std::span<const Vec2> target,
              const std::vector<bool>& active);
  bool held(int i) const { return held_[static_cast<std::size_t>(i)] != 0; }
  Vec2 hold_point(int i) const { return hold_[static_cast<std::size_t>(i)]; }
  std::span<const Passage> passages() const { return passages_; }
  bool empty() const { return passages_.empty(); }

 private:
  void update_one(double t, Passage& p, std::span<const Agent> agents, std::span<const Vec2> target,
                  const std::vector<bool>& active);

  // In a passage one figure wide, the owner's figure outside it that is
  // nearest its mouth (the next to go in); -1 for a wider one.
  int single_file(const Passage& p, std::span<const Agent> agents) const;

  std::vector<Passage> passages_;
  double avoid_radius_;
  PassageParams params_;
  std::vector<char> held_;
  std::vector<Vec2> hold_;
  // Per agent: its direction (+1, -1) while it asks for the passage at hand, else 0.
  std::vector<signed char> dir_of_;
  // Per agent: queued at a one-lane mouth (1 since the last update, 2 this
  // one), and where it stands in the queue.
  std::vector<char> queued_;
  std::vector<Vec2> queue_at_;
};

}  // namespace animrt::herd
