#include "animrt/runtime/ltc_chase.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace animrt {
namespace {

constexpr double kJumpFrames = 1.5;
constexpr double kDropoutFrames = 2.5;
// Timecode counts the hours of a day: after 23:59:59 comes 00:00:00.
constexpr double kDayS = 24 * 3600.0;

}  // namespace

LtcChase::LtcChase(double fps, double freewheel_s, std::vector<TimecodeCue> cues)
    : frame_s_(1.0 / fps), freewheel_s_(freewheel_s), cues_(std::move(cues)) {
  std::stable_sort(cues_.begin(), cues_.end(), [](const TimecodeCue& a, const TimecodeCue& b) {
    return a.start_s < b.start_s;
  });
}

void LtcChase::frame(double timecode_s, double end_s) {
  ++frames_;
  // The frame's timecode is its start's; at its end the next frame begins.
  const double at_end = timecode_s + frame_s_;
  if (locked_) {
    const double expected = anchor_tc_ + (end_s - anchor_at_);
    // Across midnight the timecode runs on: compared within a day.
    if (std::abs(std::remainder(at_end - expected, kDayS)) > kJumpFrames * frame_s_) {
      ++jumps_;
      resync_ = true;
    }
  } else {
    resync_ = true;  // first lock, or lock regained after a loss
  }
  locked_ = true;
  anchor_tc_ = at_end;
  anchor_at_ = end_s;
}

int LtcChase::advance(double now_s) {
  if (!locked_) {
    position_.reset();
    return -1;
  }
  // (A late frame from before a silence does not end the dropout.)
  const double silent = now_s - anchor_at_;
  if (silent <= kDropoutFrames * frame_s_) {
    in_dropout_ = false;
  } else if (!in_dropout_) {
    in_dropout_ = true;
    ++dropouts_;
  }
  if (silent > freewheel_s_) {
    locked_ = false;
    ++losses_;
    position_.reset();
    return -1;
  }
  const double now_tc = std::fmod(anchor_tc_ + silent, kDayS);
  int entry = -1;
  if (resync_ || !position_) {
    entry = playing_at(now_tc);
    resync_ = false;
  } else if (now_tc < *position_ - kDayS / 2) {
    // Past midnight: the cues from the day's start, else the last of the
    // day before.
    entry = due(-1.0, now_tc);
    if (entry < 0) entry = due(*position_, kDayS);
  } else {
    entry = due(*position_, now_tc);
  }
  position_ = now_tc;
  if (entry < 0) return -1;
  offset_ = now_tc - cues_[static_cast<std::size_t>(entry)].start_s;
  if (offset_ < 0.0) offset_ += kDayS;
  return cues_[static_cast<std::size_t>(entry)].cue;
}

int LtcChase::due(double from, double to) const {
  int entry = -1;
  for (std::size_t i = 0; i < cues_.size(); ++i) {
    if (cues_[i].start_s > from && cues_[i].start_s <= to) entry = static_cast<int>(i);
  }
  return entry;
}

int LtcChase::playing_at(double t) const {
  int entry = -1;
  for (std::size_t i = 0; i < cues_.size(); ++i) {
    if (cues_[i].start_s <= t) entry = static_cast<int>(i);
  }
  return entry;
}

std::optional<double> parse_timecode(const std::string& text, double fps) {
  int h = 0, m = 0, s = 0, f = 0;
  char sep = 0;
  int used = 0;
  if (std::sscanf(text.c_str(), "%2d:%2d:%2d%c%2d%n", &h, &m, &s, &sep, &f, &used) != 5 ||
      used != static_cast<int>(text.size()) || (sep != ':' && sep != ';') || h > 23 || m > 59 ||
      s > 59 || f >= std::ceil(fps) || h < 0 || m < 0 || s < 0 || f < 0) {
    return std::nullopt;
  }
  return h * 3600.0 + m * 60.0 + s + f / fps;
}

}  // namespace animrt
