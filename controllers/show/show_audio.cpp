// A show's sound track: the schedule (which track frame sounds at which show
// frame) and the player thread that feeds it to a sink.

#include "animrt/controllers/show/show_audio.hpp"

#include <sndfile.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {

AudioTrack load_audio_track(const std::string& path) {
  // One loader for every sound file the runtime reads: the head's (regular
  // file under a size limit, header rate and channels checked before any
  // allocation, truncation, NaN samples), mixed down to mono.
  head::Audio audio = head::load_audio(path);
  return AudioTrack{audio.sample_rate, std::move(audio.samples)};
}

ShowAudioSchedule::ShowAudioSchedule(const ShowAudio& audio, bool loop, double show_duration_s,
                                     int rate, std::int64_t track_frames)
    : rate_(rate),
      offset_(std::llround(audio.offset_s * rate)),
      period_(loop ? std::llround(show_duration_s * rate) : 0),
      length_(track_frames) {}

std::int64_t ShowAudioSchedule::track_frame(std::int64_t show_frame) const {
  if (show_frame < 0) return -1;
  if (period_ > 0) show_frame %= period_;
  const std::int64_t k = show_frame - offset_;
  return k >= 0 && k < length_ ? k : -1;
}

void ShowAudioSchedule::render(std::span<const float> track, std::int64_t first_show_frame,
                               std::span<float> out) const {
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::int64_t k = track_frame(first_show_frame + static_cast<std::int64_t>(i));
    out[i] = k >= 0 && k < static_cast<std::int64_t>(track.size())
                 ? track[static_cast<std::size_t>(k)]
                 : 0.0f;
  }
}

ShowAudioPlayer::ShowAudioPlayer(const ShowFile& show, AudioTrack track,
                                 std::unique_ptr<AudioSink> sink, const Clock& clock,
                                 bool own_thread)
    : track_(std::move(track)),
      schedule_(show.audio, show.loop, show.duration_s, track_.rate,
                static_cast<std::int64_t>(track_.samples.size())),
      sink_(std::move(sink)),
      clock_(clock),
      playhead_(show.duration_s, show.loop),
      buffer_(static_cast<std::size_t>(std::max(1, track_.rate / 100))),  // 10 ms per write
      show_file_(show.file) {
  if (own_thread) thread_ = std::thread([this] { run(); });
}

ShowAudioPlayer::~ShowAudioPlayer() {
  quit_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

bool ShowAudioPlayer::control(const ShowCommand& command, double t) {
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) >= kCommands) return false;
  commands_[head % kCommands] = TimedCommand{command, t};
  head_.store(head + 1, std::memory_order_release);
  return true;
}

void ShowAudioPlayer::run() {
  while (!quit_.load(std::memory_order_acquire)) {
    if (!pump()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

bool ShowAudioPlayer::take_commands(bool& seeked) {
  bool moved = false;
  seeked = false;
  for (std::uint64_t tail = tail_.load(std::memory_order_relaxed);
       tail != head_.load(std::memory_order_acquire); ++tail) {
    const TimedCommand c = commands_[tail % kCommands];
    tail_.store(tail + 1, std::memory_order_release);
    const bool was_paused = playhead_.paused();
    const double was_at = playhead_.time(c.t);
    playhead_.control(c.command, c.t);
    seeked = seeked || c.command.seeks != seeks_;
    seeks_ = c.command.seeks;
    // A play while playing (the dashboard sends the whole transport) moves nothing.
    moved =
        moved || playhead_.paused() != was_paused || std::abs(playhead_.time(c.t) - was_at) > 1e-9;
  }
  return moved;
}

// The sound runs on the output's clock: blocks follow each other without a
// gap, and where the output is heard is published for the motion to follow.
// The sound is placed (from the playhead, plus the drift so far) only at the
// start, after the transport moved, or when it is heard far from where it
// should be (this thread or the output stalled).
bool ShowAudioPlayer::pump() {
  const Nanos origin = origin_.load(std::memory_order_acquire);
  if (origin == kNotStarted || stopped_.load(std::memory_order_acquire)) return false;
  const int rate = schedule_.rate();
  std::int64_t queued = sink_->queued_frames();
  const Nanos stamp = clock_.now();
  bool seeked = false;
  if (take_commands(seeked)) {
    // What is queued belongs to the transport before the commands: it goes.
    sink_->flush();
    queued = 0;
    next_ = -1;
    if (seeked) drift_s_ = 0.0;  // the motion's seek forgets its drift too
  }
  const std::uint64_t taken = tail_.load(std::memory_order_relaxed);
  const double at = playhead_.time(to_seconds(stamp - origin));
  if (playhead_.paused()) {
    sound_.publish({at, stamp, false, taken});
    std::fill(buffer_.begin(), buffer_.end(), 0.0f);
    sink_->write(buffer_);
    next_ = -1;
    return true;
  }
  const double due = at + drift_s_;  // where the sound should be heard now
  if (next_ >= 0 && std::abs(static_cast<double>(next_ - queued) / rate - due) > kStallS)
    next_ = -1;
  if (next_ < 0) next_ = std::llround(due * rate) + queued;
  const double heard = static_cast<double>(next_ - queued) / rate;
  drift_s_ = heard - at;
  sound_.publish({heard, stamp, true, taken});
  schedule_.render(track_.samples, next_, buffer_);
  sink_->write(buffer_);
  next_ += static_cast<std::int64_t>(buffer_.size());
  played_.fetch_add(static_cast<std::int64_t>(buffer_.size()), std::memory_order_acq_rel);
  return true;
}

std::vector<std::unique_ptr<ShowAudioPlayer>> open_show_audio(
    const std::vector<std::string>& show_files, bool lockstep, const AudioSinkFactory& open_sink,
    const Clock& clock, const std::function<void(const std::string&)>& log) {
  std::vector<std::unique_ptr<ShowAudioPlayer>> players;
  for (const std::string& file : show_files) {
    const ShowFile show = load_show_file(file);
    if (!show.has_audio) continue;
    if (lockstep) {
      log("audio: " + show.audio.file + " not played (a lockstep run is not in real time)");
      continue;
    }
    AudioTrack track = load_audio_track(show.audio.file);
    try {
      std::unique_ptr<AudioSink> sink = open_sink(track.rate);
      players.push_back(
          std::make_unique<ShowAudioPlayer>(show, std::move(track), std::move(sink), clock));
      log("audio: " + show.audio.file + " starts at show time " +
          format_number(show.audio.offset_s) + " s");
    } catch (const DeviceError& e) {
      log("audio: cannot play " + show.audio.file + " (" + e.what() +
          "); the show runs without sound");
    }
  }
  return players;
}

}  // namespace animrt
