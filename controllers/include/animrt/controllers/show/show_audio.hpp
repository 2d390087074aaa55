#pragma once
// A show's sound track, played in step with the show. The schedule says which
// sample of the track sounds at which show time (pure arithmetic on frame
// counts, tested without a sound card); the player is a normal-priority
// thread that feeds ALSA from that schedule once the show has started, and
// follows the show's transport (a dashboard's pause, seek and play): it keeps
// a ShowPlayhead that gets the show's commands at the same motion times.
// The sound runs on the output's clock, never re-placed for drift: where it
// is heard is published (SoundClock) and the show's motion follows it.
//
// Show frame f is show time f / rate. Track frame (f - offset) sounds at show
// frame f: silence before the offset and after the track's end. A looping
// show restarts its track on every pass (show frames wrap at the show's
// duration), so a track longer than a pass is cut at the wrap.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/show/show_file.hpp"
#include "animrt/controllers/show/show_playhead.hpp"
#include "animrt/controllers/show/sound_clock.hpp"
#include "animrt/core/clock.hpp"

namespace animrt {

// The sound of a file, mixed down to one channel (libsndfile).
struct AudioTrack {
  int rate = 0;  // Hz
  std::vector<float> samples;
};
// Throws InputError (file and key unknown here: the show file validated it).
AudioTrack load_audio_track(const std::string& path);

class ShowAudioSchedule {
 public:
  ShowAudioSchedule(const ShowAudio& audio, bool loop, double show_duration_s, int rate,
                    std::int64_t track_frames);
  // The track frame that sounds at show frame `show_frame`, or -1 (silence).
  std::int64_t track_frame(std::int64_t show_frame) const;
  // Fills `out` with the sound of show frames first_show_frame, +1, ...
  void render(std::span<const float> track, std::int64_t first_show_frame,
              std::span<float> out) const;
  int rate() const { return rate_; }

 private:
  int rate_;
  std::int64_t offset_;  // frames
  std::int64_t period_;  // frames per pass of a looping show, 0 = not looping
  std::int64_t length_;  // frames in the track
};

// Where the sound goes. The ALSA sink is the real one; tests may use others.
class AudioSink {
 public:
  virtual ~AudioSink() = default;
  // Frames written but not yet heard (the output's latency right now).
  virtual std::int64_t queued_frames() = 0;
  // Blocks until the frames are queued.
  virtual void write(std::span<const float> mono) = 0;
  // Drops what is queued and not yet heard (a pause or a seek is heard at
  // once); queued_frames() is 0 after it.
  virtual void flush() {}
};
// Opens an ALSA playback device (e.g. "default") for mono float at `rate`.
// Throws DeviceError with ALSA's reason (no sound card, busy, ...); ALSA's
// own diagnostics are kept off stderr, so the caller reports it once.
std::unique_ptr<AudioSink> open_alsa_sink(const std::string& device, int rate);
// A stand-in for a sound card: writes what it would play to `path` as raw
// s16le mono at `rate`, in real time (controllers/show/file_sink.cpp).
// Throws DeviceError naming the file when it cannot be written.
std::unique_ptr<AudioSink> open_file_sink(const std::string& path, int rate);

class ShowAudioPlayer {
 public:
  // The sink is opened by the caller (so a missing sound card is reported
  // before the run starts); `clock` is the clock of the origin given to
  // start() (CLOCK_MONOTONIC in a real-time run). Without `own_thread` the
  // caller calls pump() itself (a test on a simulated clock).
  ShowAudioPlayer(const ShowFile& show, AudioTrack track, std::unique_ptr<AudioSink> sink,
                  const Clock& clock, bool own_thread = true);
  ~ShowAudioPlayer();
  ShowAudioPlayer(const ShowAudioPlayer&) = delete;
  ShowAudioPlayer& operator=(const ShowAudioPlayer&) = delete;

  // From the control loop: no lock, no allocation, no blocking. start()
  // gives the clock time of motion time 0 (the show's time 0 until a
  // command moves it).
  void start(Nanos show_origin) { origin_.store(show_origin, std::memory_order_release); }
  void stop() { stopped_.store(true, std::memory_order_release); }
  // The show's transport command as the show took it, at motion time `t`
  // (RunOptions::on_show_command). While paused the player writes silence;
  // a pause or a seek drops what the sink still holds; a play goes on from
  // the playhead. From one thread (the cycle); false when the player has
  // fallen kCommands behind (the command is lost).
  bool control(const ShowCommand& command, double t);

  // Show frames written to the sink so far (for tests and the report).
  std::int64_t frames_played() const { return played_.load(std::memory_order_acquire); }

  // The show time the sink is heard at, for the show's motion to follow
  // (MotionSource::follow_sound).
  const SoundClock& sound_clock() const { return sound_; }
  const std::string& show_file() const { return show_file_; }

  // One block: the commands taken, where the sound is heard now published,
  // the next block written (the sink may block). False before start() and
  // after stop() (nothing written). The player's thread loops on it.
  bool pump();

 private:
  void run();
  // Takes the commands queued; true when the transport moved (`seeked`:
  // by a seek).
  bool take_commands(bool& seeked);

  AudioTrack track_;
  ShowAudioSchedule schedule_;
  std::unique_ptr<AudioSink> sink_;
  const Clock& clock_;
  static constexpr Nanos kNotStarted = INT64_MIN;
  std::atomic<Nanos> origin_{kNotStarted};
  std::atomic<bool> stopped_{false};
  std::atomic<bool> quit_{false};
  std::atomic<std::int64_t> played_{0};
  // The commands in order, from the cycle to the player's thread (one
  // producer, one consumer; a slot is the producer's until `head_` passes
  // it, then the consumer's until `tail_` does).
  static constexpr std::size_t kCommands = 64;
  // A sound heard this far from where it should be has stalled (not
  // drifted: the motion follows drift within milliseconds): placed again.
  static constexpr double kStallS = 0.05;
  struct TimedCommand {
    ShowCommand command;
    double t = 0.0;
  };
  std::array<TimedCommand, kCommands> commands_{};
  std::atomic<std::uint64_t> head_{0}, tail_{0};
  ShowPlayhead playhead_;  // the player thread's
  // The pump's: the show frame of the next block (-1: to be placed), and the
  // sound's time minus the playhead's (the output's clock drifting from the
  // loop's), which the sound keeps when it is placed again.
  std::int64_t next_ = -1;
  double drift_s_ = 0.0;
  std::uint32_t seeks_ = 0;
  std::vector<float> buffer_;
  std::string show_file_;
  SoundClock sound_;
  std::thread thread_;
};

// The players for the sound tracks of `show_files` (shows without one are
// skipped). A track that cannot be played, for instance on a machine without
// a sound card, is reported through `log` once and left out: the run goes on
// without sound. A lockstep run is not in real time, so it plays nothing
// (and says so).
using AudioSinkFactory = std::function<std::unique_ptr<AudioSink>(int rate)>;
std::vector<std::unique_ptr<ShowAudioPlayer>> open_show_audio(
    const std::vector<std::string>& show_files, bool lockstep, const AudioSinkFactory& open_sink,
    const Clock& clock, const std::function<void(const std::string&)>& log);

}  // namespace animrt
