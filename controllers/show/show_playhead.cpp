// A show's playhead (see show_playhead.hpp).

#include "animrt/controllers/show/show_playhead.hpp"

#include <algorithm>
#include <cmath>

namespace animrt {

void ShowPlayhead::control(const ShowCommand& command, double t) {
  const bool seek = command.seeks != seeks_;
  if (seek) {
    seeks_ = command.seeks;
    const double to = std::isfinite(command.t_s) ? std::clamp(command.t_s, 0.0, duration_) : 0.0;
    if (paused_) {
      held_ = to;
    } else {
      offset_ = to - t;
    }
  }
  if (command.playing) {
    double from = time(t);
    if (!seek && !loop_ && from >= duration_) from = 0.0;
    offset_ = from - t;
    paused_ = false;
  } else if (!paused_) {
    held_ = time(t);
    paused_ = true;
  }
}

ShowPosition ShowPlayhead::position(double t) const {
  const double raw = time(t);
  double position = raw;
  if (loop_) {
    position = std::fmod(raw, duration_);
    if (position < 0) position += duration_;
  }
  position = std::clamp(position, 0.0, duration_);
  return ShowPosition{true, !paused_ && (loop_ || raw < duration_), position, duration_};
}

}  // namespace animrt
