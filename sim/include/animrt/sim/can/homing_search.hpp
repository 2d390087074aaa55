#pragma once
// The switch search of CiA 402 homing methods 17-30 (the switch methods
// without an index pulse) as a drive performs it, over ideal switches, in
// the drive's counts:
// - 17 / 18: the negative / positive limit switch; the home is its edge.
// - 19, 20: a "positive" home switch (active above its edge), 21, 22 a
//   "negative" one; the drive moves toward the edge from the side it finds
//   itself on. The home is the edge (19, 21: the falling edge; 20, 22: the
//   rising edge; with an ideal switch one position).
// - 23-26: a home switch over part of the travel, searched first in the
//   positive direction (the positive limit switch turns the drive round);
//   23, 24 home on its lower edge, 25, 26 on its upper edge. 27-30 the same
//   searched first in the negative direction (the negative limit switch
//   turns it round); 27, 28 upper edge, 29, 30 lower edge. A drive on the
//   home switch at the start moves straight toward the edge sought.
// Moves are at constant speed: the switch speed (6099h:01) until the drive
// first turns round, the zero speed (6099h:02) after. A limit switch the
// method does not use, or one met again after turning round at it, is a
// homing error, as is a search that reaches its travel limit (kMaxTravel).

#include <cstdint>

#include "animrt/core/clock.hpp"

namespace animrt::sim {

class HomingSearch {
 public:
  struct Switches {  // counts; +-infinity where a switch is not fitted
    double home_from, home_to;
    double negative_limit, positive_limit;
  };
  enum class Phase : std::uint8_t { searching, attained, error };

  static bool is_switch_method(int method) { return method >= 17 && method <= 30; }
  HomingSearch(int method, const Switches& switches, double start, double switch_speed,
               double zero_speed, Nanos now);

  // Moves on to `now` (events at their exact positions).
  void advance(Nanos now);
  double position() const { return position_; }
  Phase phase() const { return phase_; }

 private:
  // The next event within `travel` ahead: its distance, or travel if none.
  double next_event(double travel, int& kind) const;

  Switches sw_;
  double target_;      // the edge that is the home
  int turn_at_ = 0;    // +1 / -1: that limit switch turns the drive round; 0: none
  int direction_ = 1;  // +1 / -1
  bool turned_ = false;
  double switch_speed_, zero_speed_;  // counts/s
  double position_;
  double travelled_ = 0.0;
  Nanos time_;
  Phase phase_ = Phase::searching;
};

}  // namespace animrt::sim
