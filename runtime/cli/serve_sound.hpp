#pragma once
// `animrt serve`'s sound: the sound tracks of the cues' shows, each on its
// own player, told by the cue player when to play (cue_player.hpp).

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "animrt/core/clock.hpp"

namespace animrt {
class CuePlayer;
class ShowAudioPlayer;
}  // namespace animrt

namespace animrt::cli {

struct SoundArgs {
  bool no_audio = false;
  std::string device = "default";  // ALSA playback device
};

void add_sound_options(CLI::App* cmd, SoundArgs& args);

class ServeSound {
 public:
  // Opens a player for every show with a sound track that a cue plays (a
  // sound that cannot be played is warned of once and left out) and hands
  // them to `cues`. A lockstep run plays none.
  ServeSound(const SoundArgs& args, bool lockstep, CuePlayer& cues);
  ~ServeSound();
  // The motion's start and end (RunOptions::on_motion_start/end).
  void start(Nanos t0);
  void stop();

 private:
  MonotonicClock clock_;  // the run's (real-time runs only play sound)
  std::vector<std::unique_ptr<ShowAudioPlayer>> players_;
};

}  // namespace animrt::cli
