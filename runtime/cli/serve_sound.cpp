#include "serve_sound.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/show/show_audio.hpp"

namespace animrt::cli {

void add_sound_options(CLI::App* cmd, SoundArgs& args) {
  cmd->add_flag("--no-audio", args.no_audio, "do not play the cues' sound tracks");
  cmd->add_option("--audio-device", args.device, "ALSA playback device for the cues' sound tracks")
      ->capture_default_str();
}

ServeSound::ServeSound(const SoundArgs& args, bool lockstep, CuePlayer& cues) {
  if (args.no_audio) return;
  std::vector<std::string> shows;
  for (const Cue& cue : cues.cues()) {
    for (const CueStep& step : cue.steps) {
      if (!step.show_file.empty() &&
          std::find(shows.begin(), shows.end(), step.show_file) == shows.end())
        shows.push_back(step.show_file);
    }
  }
  const std::string device = args.device;
  players_ = open_show_audio(
      shows, lockstep, [device](int rate) { return open_alsa_sink(device, rate); }, clock_,
      [](const std::string& line) { spdlog::warn("{}", line); });
  for (auto& player : players_) cues.play_sound(player->show_file(), *player);
}

ServeSound::~ServeSound() = default;

void ServeSound::start(Nanos t0) {
  for (auto& player : players_) player->start(t0);
}

void ServeSound::stop() {
  for (auto& player : players_) player->stop();
}

}  // namespace animrt::cli
