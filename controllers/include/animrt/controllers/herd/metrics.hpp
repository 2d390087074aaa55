#pragma once
// What a herd run is judged by, sampled at every output step: figures that
// touch (pairs closer than the sum of their radii, whatever their groups),
// how ordered each group walks (over its moving figures only: standing
// figures have no direction to agree on), how fast it walks against its
// leader, how tight it keeps, how far a flock is from its leader, and for
// crowds the arrivals, their times and detours, and the figures that got
// stuck.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"

namespace animrt::herd {

struct GroupMetrics {
  std::string name;
  std::string kind;
  int agents = 0;
  long collisions = 0;               // agent-pair-steps with one member in this group
  double min_pair_distance_m = 0.0;  // centre distance, over pairs touching this group that came
                                     // within two figure widths (has_pair false: none did)
  bool has_pair = false;
  // Velocities v are each figure's displacement since the previous sample
  // over the time between (what it walked, not what its gait was asked).
  double order_mean = 0.0;      // |sum v| / (N mean |v|) over moving members, mean over steps after
                                // settling with at least two moving
  double order_min = 0.0;       // its minimum over those steps
  long order_steps = 0;         // steps the order was measured in (0: not measured)
  double speed_mean_mps = 0.0;  // mean |v| of all members, over steps after settling
  double leader_speed_mean_mps = -1.0;  // flocks: the leader's, over the same steps (-1: none)
  bool standing = false;  // mean speed under a tenth of the leader's: order means nothing
  double nearest_neighbour_mean_m = 0.0;  // within the group, mean over steps
  bool has_neighbour = false;             // false: a group of one, nothing measured
  double leader_distance_mean_m = -1.0;   // flocks: centre to leader (-1: no leader)
  double leader_distance_max_m = -1.0;
  // Crowds (arrivals -1 for flocks):
  int arrivals = -1;  // the times and ratios below only mean something when above 0
  double time_to_goal_mean_s = 0.0;
  double time_to_goal_max_s = 0.0;
  double time_ratio_max = 0.0;   // time to goal / straight-line time (distance / max speed)
  double path_ratio_mean = 0.0;  // walked length / straight-line length
  double path_ratio_max = 0.0;
  int stuck = 0;  // agents that never arrived and once moved less than one radius in 5 s
};

struct HerdMetrics {
  double duration_s = 0.0;
  long steps = 0;                    // output steps sampled
  long collisions = 0;               // agent-pair-steps, whole scene
  double min_pair_distance_m = 0.0;  // closest two figures ever came (has_pair false: fewer
                                     // than two figures, nothing measured)
  double min_clearance_m = 0.0;      // min over pairs of distance - sum of radii
  bool has_pair = false;
  long contact_stops = 0;  // figure-steps stopped by the herd's contact guard
  long knots = 0;          // knots of crowd members found and backed off (crowd.hpp)
  std::vector<GroupMetrics> groups;
};

// What the metrics need to know of each group.
struct GroupInfo {
  std::string name;
  std::string kind;
  std::vector<int> members;
  std::optional<Vec2> target;  // crowds
};

class MetricsRecorder {
 public:
  // `settle_s`: order figures count only after this time (a flock forms).
  MetricsRecorder(std::vector<GroupInfo> groups, std::span<const Agent> start, double settle_s);

  // One output step at time t. `leaders[g]` is group g's leader position
  // when it has one; `arrived[i]` whether agent i is at its goal; `max_speed[i]`
  // the fastest it may walk (for the straight-line time).
  void sample(double t, std::span<const Agent> agents, std::span<const std::optional<Vec2>> leaders,
              std::span<const char> arrived, std::span<const double> max_speed);

  HerdMetrics finish() const;
  void set_contact_stops(long stops) { contact_stops_ = stops; }
  void set_knots(long knots) { knots_ = knots; }

 private:
  struct AgentTrack {
    Vec2 start;
    Vec2 last;
    double walked = 0.0;
    double arrived_at = -1.0;
    double walked_at_arrival = 0.0;
    bool stuck = false;
    Vec2 anchor;  // position at anchor_t, for the stuck test
    double anchor_t = 0.0;
  };
  struct GroupSums {
    long collisions = 0;
    double min_pair = 1e300;
    double order_sum = 0.0, order_min = 1e300;
    long order_steps = 0;
    double speed_sum = 0.0;
    long speed_steps = 0;
    double leader_walked = 0.0, leader_time = 0.0;
    std::optional<Vec2> leader_last;
    double leader_last_t = 0.0;
    double nn_sum = 0.0;
    long nn_steps = 0;
    double leader_sum = 0.0, leader_max = -1.0;
    long leader_steps = 0;
  };

  std::vector<GroupInfo> groups_;
  std::vector<int> group_of_;
  std::vector<AgentTrack> tracks_;
  std::vector<GroupSums> sums_;
  std::vector<double> max_speed_;
  double settle_s_;
  double last_t_ = 0.0;
  long steps_ = 0;
  long collisions_ = 0;
  long contact_stops_ = 0;
  long knots_ = 0;
  double min_pair_ = 1e300;
  double min_clearance_ = 1e300;
  std::vector<int> order_;  // scratch: agents sorted by x
};

}  // namespace animrt::herd
