#pragma once
// A show's playhead: the show's time as a function of the motion's time,
// moved by a dashboard's play, pause and seek (ShowCommand). A show source
// and the player of its sound track each keep one and get the same commands
// at the same motion times, so the sound stays where the show is. Plain
// arithmetic: no allocation, lock or I/O.

#include <cstdint>

#include "animrt/controllers/motion_source.hpp"

namespace animrt {

class ShowPlayhead {
 public:
  ShowPlayhead(double duration_s, bool loop) : duration_(duration_s), loop_(loop) {}

  // The command at motion time `t`: a seek moves the show's time to t_s
  // (clamped to the show), a pause holds it, a play lets it advance again (a
  // non-looping show that has ended plays again from its start).
  void control(const ShowCommand& command, double t);

  // The show's time at motion time t, not wrapped (a looping show's passes
  // go on counting): held while paused, else t moved by the seeks and
  // pauses so far.
  double time(double t) const { return paused_ ? held_ : t + offset_; }
  // Moves the show's time by ds, as if it had run that much faster (a
  // sound track's clock pulling it along). A seek forgets the nudges.
  void nudge(double ds) {
    if (paused_) {
      held_ += ds;
    } else {
      offset_ += ds;
    }
  }
  bool paused() const { return paused_; }
  // Within [0, duration], wrapped for a looping show; playing: not paused
  // and not past a non-looping show's end.
  ShowPosition position(double t) const;

  double duration_s() const { return duration_; }
  bool loop() const { return loop_; }

 private:
  double duration_;
  bool loop_;
  bool paused_ = false;
  double held_ = 0.0;    // the show's time while paused
  double offset_ = 0.0;  // show time minus motion time while playing
  std::uint32_t seeks_ = 0;
};

}  // namespace animrt
