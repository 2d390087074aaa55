#include "serve_sound.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/show/show_audio.hpp"

namespace animrt::cli {

void add_sound_options(CLI::App* cmd, SoundArgs& args) {
  cmd->add_flag("--no-audio", args.no_audio, "do not play the cues' sound tracks");
  cmd->add_option("--audio-device", args.device,
                  "where the cues' sound tracks play: an ALSA device, or file:FOLDER (each "
                  "show's track as FOLDER/SHOW.s16: raw s16le mono at the track's rate, written "
                  "in real time as a sound card would play it)")
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
  const auto warn = [](const std::string& line) { spdlog::warn("{}", line); };
  // One show at a time, so that a folder output knows whose file it opens.
  for (const std::string& show : shows) {
    const auto open_sink = [&args, &show](int rate) {
      constexpr std::string_view kFolder = "file:";
      if (args.device.rfind(kFolder, 0) != 0) return open_alsa_sink(args.device, rate);
      const std::filesystem::path folder = args.device.substr(kFolder.size());
      return open_file_sink((folder / std::filesystem::path(show).stem()).string() + ".s16", rate);
    };
    for (auto& player : open_show_audio({show}, lockstep, open_sink, clock_, warn)) {
      cues.play_sound(player->show_file(), *player);
      players_.push_back(std::move(player));
    }
  }
}

ServeSound::~ServeSound() = default;

void ServeSound::start(Nanos t0) {
  for (auto& player : players_) player->start(t0);
}

void ServeSound::stop() {
  for (auto& player : players_) player->stop();
}

}  // namespace animrt::cli
