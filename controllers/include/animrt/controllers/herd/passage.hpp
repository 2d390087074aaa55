#pragma once
// Right of way at narrow passages: where two walls (at any angle) leave a
// gap too narrow for two streams to pass each other, the gap is used one
// way at a time.
// Each passage decides for itself (no central schedule): the first figure
// to come near takes it for its direction; figures the other way wait
// beside the mouth, clear of the way out; once the other way has waited
// max_hold_s the passage admits no new figures of the owning direction,
// and when the last of them is through, ownership swaps.

#include <array>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

class NavWorld;

struct PassageParams {
  // Gaps narrower than this many avoidance radii are passages (two
  // figures side by side need four, and room to pass them two more).
  double max_width_radii = 6.5;
  double approach_m = 6.0;  // figures this far from a mouth ask for the passage
  // Figures this near a mouth go on through when their way closes; a
  // figure keeps asking for the passage until clear_m out of the far mouth
  // (its way keeps the passage while the other way does not ask), though
  // once out of the mouth it no longer holds up a swap. Near is measured
  // along the passage's axis only, and the waiting places (wait_back_m
  // out) lie within it: a figure the closing holds walks to its place and
  // goes on from there, so a team of two dozen passes whole before the
  // swap. Measured sideways too, the ways took turns and lost
  // (docs/results/herds.md, "Turns at the gap").
  double close_m = 2.5;
  double clear_m = 1.5;
  double max_hold_s = 60.0;  // the other way waits at most this long for a turn
  // The other way waits round a place this far (m) out from the mouth,
  // plus an avoidance radius, and this far to the side of the passage's
  // edge: near the wall's face and well aside, its waiting crowd (two
  // dozen figures stand 2-2.5 m round it) keeps clear of the way in to
  // the mouth as well as of the way out.
  double wait_back_m = 1.5;
  double wait_aside_m = 4.0;
  // At a passage one figure wide, the owner's figures this near its mouth
  // queue there and go in one at a time.
  double queue_m = 1.5;
};

struct Passage {
  Vec2 centre;
  Vec2 axis;  // through the passage (unit)
  double half_width = 0.0;
  double half_length = 0.0;
  int owner = 0;  // +1: along axis, -1: against it, 0: free (its chain's way, PassageChain)
  // Per way (+1, -1): the side its figures wait on, +1 right, -1 left, 0
  // not decided yet.
  int wait_side[2] = {0, 0};
};

// Passages in a row (a narrow corridor that turns, gaps close one after
// another) take turns as one: a figure out of one is straight away asking
// for the next, with no room between to wait aside, and two ways that
// each held one of them stood nose to nose between them for good. A
// chain's passages follow each other mouth to mouth, each far mouth
// facing the next one's near mouth within approach_m; a mouth that more
// passages face (a junction) links none.
struct PassageChain {
  std::vector<int> members;     // passages, in order along the chain
  std::vector<int> orient;      // per member: its way (+1, -1) when the chain's way is +1
  int owner = 0;                // the chain's way: +1, -1, or 0 free
  double waiting_since = -1.0;  // when the other way began to wait, or -1
  bool closing = false;         // the owner admits no one new
};

// A wall as the passage finder measures it: its corners (counter-clockwise)
// and its extent along its own two axes.
struct WallExtent {
  std::array<Vec2, 4> corner;
  Vec2 ax, ay;
  double a0 = 0.0, a1 = 0.0, b0 = 0.0, b1 = 0.0;  // dot(p, ax) in [a0, a1], dot(p, ay) in [b0, b1]
};

// Gaps narrower than max_width between two walls at any angle. A passage
// runs across the way between the walls' nearest points, along the
// stretch where both walls face each other and the gap stays under
// max_width: for two parallel walls their whole overlap, for slanted ones
// the stretch round the narrowest point (its half_width is there).
std::vector<Passage> find_passages(std::span<const Box> walls, double max_width);

// The chains of `passages` (every passage is in one; most in one of their
// own): mouths linked where `distance` between them (by the mesh, or
// straight) is at most link_m and each faces the other.
std::vector<PassageChain> find_chains(
    std::span<const Passage> passages, double link_m,
    const std::function<std::optional<double>(Vec2, Vec2)>& distance);

class PassageRules {
 public:
  // With a world, the waiting places follow the way out where the walls
  // turn it and move where walls leave no room (choose_side,
  // find_wait_place); without one, figures wait on their right.
  PassageRules(std::span<const Box> walls, double avoid_radius, PassageParams params = {},
               const NavWorld* world = nullptr);

  // Decides, for every active agent walking to target[i], whether it must
  // wait, and where (hold_point).
  void update(double t, std::span<const Agent> agents, std::span<const Vec2> target,
              const std::vector<bool>& active);
  bool held(int i) const { return held_[static_cast<std::size_t>(i)] != 0; }
  Vec2 hold_point(int i) const { return hold_[static_cast<std::size_t>(i)]; }
  std::span<const Passage> passages() const { return passages_; }
  std::span<const PassageChain> chains() const { return chains_; }
  // Whether a figure of `radius` at q stands in a passage or in one of its
  // doorways (less than a figure's width out of a mouth, as wide as the
  // passage): where every figure that passes must walk.
  bool in_way(Vec2 q, double radius) const;
  bool empty() const { return passages_.empty(); }

 private:
  // Who asks for passage `index` (and how near), per way.
  struct Count {
    int want[2] = {0, 0};  // asking for the passage
    int in[2] = {0, 0};    // near its mouth or in it
    double nearest[2] = {0.0, 0.0};
  };
  Count count_one(double t, int index, const Passage& p, std::span<const Agent> agents,
                  std::span<const Vec2> target, const std::vector<bool>& active);
  // Whose turn it is at a chain (its passages take it on).
  void take_turns(double t, int chain, std::span<const Agent> agents);
  // Holds the figures passage `index` makes wait, and says where.
  void hold_one(int index, const Passage& p, std::span<const Agent> agents,
                std::span<const Vec2> target);

  // In a passage one figure wide, the owner's figure outside it that is
  // nearest its mouth (the next to go in); -1 for a wider one.
  int single_file(const Passage& p, std::span<const Agent> agents) const;

  // Whether the figure at pos sees the mouth of p on its side (no wall
  // between it and the mouth's nearest point).
  bool sees(const Passage& p, Vec2 pos) const;
  // The way (+1, -1) a figure at pos walking to goal goes through p, or
  // 2 when its way does not lead through it: by the mesh's shortest
  // paths (a maze turns ways round wall ends), else by the goal's side.
  signed char way_through(const Passage& p, Vec2 pos, Vec2 goal) const;
  // The same from side `from` (+1, -1) of the passage.
  signed char way_through(const Passage& p, Vec2 pos, Vec2 goal, int from) const;
  // For a figure round a corner from p: its side is the mouth nearer by the
  // mesh (`to` away); 0 while that is farther than approach_m.
  signed char way_round(const Passage& p, Vec2 pos, Vec2 goal, double& to) const;
  // Where figures of way dir wait for passage `index` on side +1 (right)
  // or -1 (left): found once for each passage, way and side
  // (find_wait_place), in places_.
  Vec2 wait_place(int index, int dir, int side) const;
  // A waiting place, and whether it is clear (else it is the first place
  // tried, snapped to the mesh where the mesh is within reach).
  struct WaitPlace {
    Vec2 at;
    bool clear = true;
  };
  WaitPlace find_wait_place(const Passage& p, int dir, int side) const;
  int choose_side(int index, int dir, std::span<const Agent> agents, std::span<const Vec2> target);

  std::vector<Passage> passages_;
  std::vector<PassageChain> chains_;
  std::vector<int> chain_of_;  // per passage
  std::vector<Count> counts_;  // per passage, this update
  std::vector<WallExtent> walls_;
  std::vector<std::array<WaitPlace, 4>> places_;  // per passage (place_slot in passage.cpp)
  double avoid_radius_;
  PassageParams params_;
  const NavWorld* world_ = nullptr;
  std::vector<char> held_;
  std::vector<Vec2> hold_;
  // Per agent: the passage that holds it (this update, the last one), or -1.
  std::vector<int> held_by_, was_held_by_;
  // Per agent: the passage that holds it where it stands, round a corner
  // from it (this update, the last one), and where.
  std::vector<int> stood_by_, was_stood_by_;
  std::vector<Vec2> stand_at_;
  // Per agent and passage: the way through of a figure round a corner
  // from it (0: not decided, 2: not through), its path to the mouth, and
  // when to ask again while it is not near.
  std::vector<signed char> round_way_;
  std::vector<double> round_to_;
  std::vector<double> round_next_;
  // Per agent and passage: its way through, decided as it comes near
  // (0: not yet, 2: not through), kept while it stays near.
  std::vector<signed char> way_;
  // Per agent and passage: its direction (+1, -1) while it asks for the
  // passage, else 0; whether it asks from round a corner; whether it is
  // near the mouth or in the passage (it goes on through when it closes);
  // whether it is not yet out of the far mouth.
  std::vector<signed char> dir_of_;
  std::vector<char> round_of_;
  std::vector<char> near_;
  std::vector<char> ahead_;
  // Per agent and chain of more than one passage: the chain's way it took
  // near one of its passages (0: none), kept while it asks for any of
  // them, so a figure between two of them still counts as in the chain.
  std::vector<signed char> chain_way_;
  // Per agent: queued at a one-lane mouth (1 since the last update, 2 this
  // one), and where it stands in the queue.
  std::vector<char> queued_;
  std::vector<Vec2> queue_at_;
};

}  // namespace animrt::herd
