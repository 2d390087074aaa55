#pragma once
// Chasing SMPTE LTC timecode: from the frames an LTC decoder reads off an
// audio input, the show's timecode at any moment of that input's clock, and
// the cues bound to timecode starts that are due. The chase
// - locks on the first frame, and follows the frames as they come;
// - re-syncs when a frame disagrees with the running time by more than a
//   frame and a half (a jump: the timecode source was cued elsewhere), and
//   asks for the cue that should be playing at the new time, at the time
//   into it that the timecode says;
// - freewheels through a dropout (no frame for more than two and a half
//   frame periods, counted) on the audio clock, for up to `freewheel_s`;
//   after that the timecode is lost until frames come again.
// Plain logic on given times, so every edge is a unit test.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace animrt {

struct TimecodeCue {
  double start_s = 0.0;  // timecode seconds (hours * 3600 + ... + frames / fps)
  int cue = 0;
};

class LtcChase {
 public:
  LtcChase(double fps, double freewheel_s, std::vector<TimecodeCue> cues);

  // A frame was decoded: its timecode (s) and the input time (s) at its end.
  void frame(double timecode_s, double end_s);
  // The input has reached time `now_s`: the cue to ask for now, or -1. Call
  // after the frames decoded up to `now_s`.
  int advance(double now_s);
  // The time into the cue the last advance() asked for, at `now_s` (s).
  double cue_offset() const { return offset_; }

  // The chased timecode at the last advance(), empty when not locked.
  std::optional<double> timecode() const { return position_; }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t jumps() const { return jumps_; }
  std::uint64_t dropouts() const { return dropouts_; }
  std::uint64_t losses() const { return losses_; }

 private:
  // Indices into cues_, or -1.
  int due(double from, double to) const;  // the last cue starting in (from, to]
  int playing_at(double t) const;         // the last cue starting at or before t

  double frame_s_;
  double freewheel_s_;
  std::vector<TimecodeCue> cues_;  // by start
  bool locked_ = false;
  bool resync_ = false;
  bool in_dropout_ = false;
  double anchor_tc_ = 0.0;  // timecode at input time anchor_at_
  double anchor_at_ = 0.0;
  std::optional<double> position_;
  double offset_ = 0.0;
  std::uint64_t frames_ = 0, jumps_ = 0, dropouts_ = 0, losses_ = 0;
};

// "HH:MM:SS:FF" (or with ';' before the frames) at `fps`, in seconds; empty
// when it is not a timecode.
std::optional<double> parse_timecode(const std::string& text, double fps);

}  // namespace animrt
