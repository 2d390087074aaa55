#pragma once
// Navigation-mesh crowds: one Detour crowd shared by every crowd group of a
// herd, so teams avoid each other, and the groups that walk in it.
//
// The herd moves its figures itself, by what their gaits achieve, so each
// step the crowd is first told where every figure really is and how fast it
// really moves (each crowd agent is slid along the mesh to the figure's
// position), then plans one step, and the planned velocities go back to the
// herd as desired velocities. Figures of other groups (flocks, the embodied
// robot) are passive crowd agents: crowd members avoid them, nothing steers
// them.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"
#include "animrt/controllers/herd/nav_world.hpp"
#include "animrt/controllers/herd/spatial_grid.hpp"

class dtCrowd;

namespace animrt::herd {

struct CrowdParams {
  int max_agents = 1024;
  // Added to every figure's radius for avoidance, so figures that lag
  // behind the plan (gait response, turn limits) still keep apart.
  double avoidance_margin_m = 0.1;
  // The figures' turn-rate limit; the crowd's acceleration is limited to
  // what such a figure can do at its top speed (max_speed * turn * accel_factor),
  // so the plan stays one the figures can follow.
  double figure_turn_rad_s = 0.6;
  double accel_factor = 2.0;
  // A standing figure walks off only when the crowd plans at least half its
  // gait's slowest walk (figure.cpp); the crowd's velocity starts from the
  // figure's every step, so its acceleration is at least this speed per
  // herd step, or a figure with a fast slowest walk would never start.
  double figure_start_speed_m_s = 0.0;
  double step_s = 0.1;
  // Separation pushes members apart over the whole collision query range
  // (12 radii): in a packed start it drives the outer ones away from their
  // goal, so it is off unless asked for; avoidance keeps them apart.
  double separation_weight = 0.0;
  double avoidance_horizon_s = 4.0;  // how far ahead avoidance looks
  // Near its target (where the gathering is, away from walls), a member
  // the avoidance holds still while its path leads on follows the path,
  // sliding along neighbours in contact (see planned_velocity).
  bool unstick = true;
  // Anywhere else, a member that has not moved 0.1 m for this long follows
  // its path the same way (0: never): the avoidance can hold a figure still
  // for good where it touches a wall corner (its avoidance radius is larger
  // than the radius the mesh keeps it from the walls by). The path may
  // graze a wall there, so only for figures kept out of walls otherwise
  // (the herd sets 5 s: it stops a figure at a wall's surface).
  double unstick_after_s = 0.0;
  // Figures closer than the sum of their radii plus this never walk
  // toward each other (see safe_velocity); 0 turns the rule off.
  double contact_margin_m = 0.1;
  // Neighbours within this many avoidance radii are avoided.
  double query_range_radii = 5.0;
  // Keep right: a member meeting an oncoming figure (heading more than
  // 120 degrees from its own way) ahead of it and less than the sum of
  // their avoidance radii to the side turns its way to the right, by up to
  // this angle (rad) as the figure comes closer (see keep_right); 0 turns
  // the rule off. Both turn, so they pass each other on the left, and in a
  // gap two opposing streams form two lanes instead of meeting head on.
  double keep_right_rad = 0.6;
  // How far ahead (m) an oncoming figure is looked for.
  double keep_right_range_m = 3.0;
  // Right of way at narrow passages (a gap between two walls narrower than
  // this many avoidance radii; 0: none): one way at a time, the other
  // waits beside the mouth, and the way swaps once the waiting side has
  // waited passage_max_hold_s (see passage.hpp).
  double passage_width_radii = 6.5;
  double passage_max_hold_s = 60.0;
  // Knots (see knot.hpp): travelling members that have not moved
  // knot_progress_m for knot_still_s (0: never looked for), standing within
  // knot_link_m of each other, are a knot; one side of it backs off.
  double knot_still_s = 30.0;
  double knot_progress_m = 0.3;
  double knot_link_m = 0.4;
  double knot_back_off_m = 1.5;
  double knot_back_off_s = 20.0;
};

class CrowdGroup;
class PassageRules;
class CellIndex;
class KnotRules;

class Crowd {
 public:
  // Registers every agent of the herd (all passive until a CrowdGroup
  // claims its members). `world` must outlive the crowd.
  Crowd(NavWorld& world, std::span<const Agent> agents, CrowdParams params = {});
  ~Crowd();
  Crowd(const Crowd&) = delete;
  Crowd& operator=(const Crowd&) = delete;

  // Advances the world's obstacles and the crowd by one step: syncs every
  // agent's position and velocity into the crowd, then plans. Called by
  // each group's steer(); only the first call for a given t does the work.
  void step(double t, double dt, std::span<const Agent> agents);

  NavWorld& world() { return world_; }
  const CrowdParams& params() const { return params_; }
  dtCrowd* native() { return crowd_; }
  std::size_t agent_count() const { return active_.size(); }
  // Knots found so far (each once, when one side of it was made to yield).
  long knots() const;

 private:
  friend class CrowdGroup;
  void sync(int i, const Agent& a);
  void make_active(int i, double max_speed);
  bool request_target(int i, Vec2 target);
  bool retarget(int i, Vec2 target);  // moves the crowd's target only (target_ stays)
  void stop(int i);
  Vec2 planned_velocity(int i, bool unstick) const;
  Vec2 safe_velocity(int i, Vec2 v, std::span<const Agent> agents) const;
  Vec2 keep_right(int i, Vec2 v, std::span<const Agent> agents) const;
  // The agents the crowd's proximity grid holds in the square of half-side
  // `range` around p, as its query returns them (at most out.size()).
  int near_agents(Vec2 p, double range, std::span<unsigned short> out) const;
  // A member the passage rules hold walks to its waiting place and stands
  // there, or where it meets one already standing.
  Vec2 passage_wait(int i, Vec2 v, std::span<const Agent> agents) const;
  void apply_passages(double t, std::span<const Agent> agents);
  // A member whose way leads through the gap a moving wall closes for now
  // waits at the wall's near face (see crowd.cpp); true with its place.
  bool wait_for_wall(double t, int i, std::span<const Agent> agents, Vec2& at);
  void apply_knots(double t, std::span<const Agent> agents);
  // Where the crowd sends member i now: its back-off point, its waiting
  // place, or its target.
  bool request_current(int i);
  // Set by its group each step: the member has not arrived (it walks to
  // its target or its slot on its own, and may be in a knot).
  void set_travelling(int i, bool travelling) {
    travelling_[static_cast<std::size_t>(i)] = travelling ? 1 : 0;
  }
  // Which agents take part in the crowd's update (see crowd.cpp).
  void select_participants();

  NavWorld& world_;
  CrowdParams params_;
  dtCrowd* crowd_ = nullptr;
  std::vector<bool> active_;
  std::vector<bool> has_target_;
  std::vector<Vec2> target_;
  std::vector<Vec2> synced_;  // each agent's position before the last crowd update
  std::vector<Vec2> facing_;  // each agent's heading vector at the last step
  std::unique_ptr<PassageRules> passages_;
  std::unique_ptr<KnotRules> knots_;
  std::vector<char> travelling_;
  std::vector<char> backing_;             // backing off out of a knot at the last step
  std::vector<char> eligible_;            // scratch: travelling members no rule holds
  std::unique_ptr<CellIndex> grid_rows_;  // the proximity grid's items at the last update
  mutable std::vector<int> near_scratch_;
  double reach_m_ = 0.0;  // a passive agent this far from every member cannot matter to one
  SpatialGrid members_near_;
  std::vector<Vec2> member_at_;
  std::vector<int> in_update_;  // the agents in the crowd's update, in its order
  std::vector<bool> asking_;    // active members with a target
  std::vector<char> was_held_;
  std::vector<Vec2> hold_at_;  // where each held member waits
  // Per member: the moving wall it waits for (-1: none), where, and per
  // member and wall the drop it was last decided for.
  std::vector<int> wall_of_;
  std::vector<Vec2> wall_at_;
  std::vector<int> wall_decided_;
  std::vector<int> wall_drop_;       // per moving wall: drops seen, counting this one
  std::vector<char> wall_was_down_;  // per moving wall: down at the last step
  struct WallGap {                   // per moving wall, from its footprint
    Vec2 across, along;              // unit axes through its thin and along its long side
    double depth = 0.0, half = 0.0;  // half its thickness and half its length
    bool closes_gap = false;         // both ends meet a static wall or the ground's edge
  };
  std::vector<WallGap> wall_gaps_;
  double dt_ = 0.0;
  double last_t_ = -1e300;
  bool stepped_ = false;
};

struct CrowdGroupParams {
  Vec2 target;
  double speed_min_mps = 0.15;  // each member's top speed is drawn from [min, max]
  double speed_max_mps = 0.25;
  std::uint64_t seed = 1;
  // Arrival slots around the target, packed this far apart; 0: two
  // avoidance radii plus 0.3 m (room to walk in between).
  double slot_spacing_m = 0.0;
  // Members within this distance of the target (0: the slots' extent plus
  // two spacings) head for a free slot at the edge of the gathering.
  double assign_distance_m = 0.0;
  double arrive_tolerance_m = 0.2;  // a member this close to its slot has arrived
  // A member that comes no closer to its goal for this long beside the
  // gathering has arrived where it stands (0: never).
  double stall_time_s = 20.0;
};

class CrowdGroup final : public GroupSteering {
 public:
  // `members` index the herd's agents (as given to the crowd); the crowd
  // must outlive the group.
  CrowdGroup(Crowd& crowd, std::span<const Agent> agents, std::vector<int> members,
             CrowdGroupParams params);

  std::span<const int> members() const override { return members_; }
  void steer(double t, double dt, std::span<const Agent> agents, std::span<Vec2> desired) override;

  // Per member k (position in members()).
  double max_speed(std::size_t k) const { return max_speed_[k]; }
  bool arrived(std::size_t k) const { return state_[k] == State::kArrived; }
  std::size_t arrived_count() const;
  // The member's slot in slots(), or -1 while it has none.
  int slot_index(std::size_t k) const { return slot_of_[k]; }
  std::span<const Vec2> slots() const { return slots_; }
  Vec2 target() const { return params_.target; }

 private:
  enum class State { kTravelling, kToSlot, kArrived };
  void make_slots(double radius);
  bool reachable(Vec2 from, std::size_t slot) const;
  // The lanes this step: one from each travelling figure of another group
  // near the target toward its target.
  void find_lanes(std::span<const Agent> agents);
  bool in_lane(Vec2 q) const;
  // Marks the open slots (but the first) that lie in a lane or a
  // passage's way in in_lane_.
  void mark_lane_slots();
  void take_slot(std::size_t slot);  // keeps open_ and taken_ with slot_taken_
  void free_slot(std::size_t slot);

  Crowd& crowd_;
  std::vector<int> members_;
  CrowdGroupParams params_;
  std::vector<double> max_speed_;
  std::vector<State> state_;
  std::vector<int> slot_of_;        // per member, -1 while travelling
  std::vector<Vec2> stall_anchor_;  // where each member was when it last moved 0.1 m (unstick)
  std::vector<double> stall_since_;
  // Per member: its goal, the closest it has come to it since it last came
  // 0.1 m closer (or fell back by half a spacing), and since when.
  std::vector<Vec2> headway_goal_;
  std::vector<double> headway_best_;
  std::vector<double> headway_since_;
  std::vector<int> candidate_;  // per travelling member: the slot it heads for, or -1
  std::vector<Vec2> slots_;     // sorted by distance from the target
  std::vector<bool> slot_taken_;
  std::vector<bool> frontier_;        // free slots that may be taken next
  std::vector<int> open_;             // free frontier slots, in index order
  std::vector<int> taken_;            // taken slots
  std::vector<std::size_t> to_slot_;  // scratch: the members heading for a slot, in order
  std::vector<std::vector<int>> neighbours_;
  std::vector<char> is_member_;  // per agent of the herd
  struct Lane {
    Vec2 from, dir;  // dir: unit
    double length = 0.0, half_width = 0.0;
  };
  std::vector<Lane> lanes_;
  std::vector<char> in_lane_;  // per slot: open and in a lane (or in_way_) this step
  std::vector<char> in_way_;   // per slot: in a narrow passage's way (never taken)
  double assign_distance_ = 0.0;
  double spacing_ = 0.0;
};

}  // namespace animrt::herd
