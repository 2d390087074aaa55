// A show's sound track: which track sample sounds at which show time (offset,
// end of track, looping), the player feeding a sink from that schedule once
// the show starts, and the no-sound-card path. No sound card is needed.

#include "animrt/controllers/show/show_audio.hpp"

#include <gtest/gtest.h>
#include <sndfile.h>

#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt {
namespace {

ShowAudio audio_at(double offset_s) {
  ShowAudio a;
  a.offset_s = offset_s;
  return a;
}

TEST(ShowAudioSchedule, TheTrackStartsAtItsOffsetAndEndsWithItsLength) {
  const ShowAudioSchedule s(audio_at(0.25), false, 10.0, 1000, 500);
  EXPECT_EQ(s.track_frame(-1), -1);
  EXPECT_EQ(s.track_frame(0), -1);
  EXPECT_EQ(s.track_frame(249), -1);
  EXPECT_EQ(s.track_frame(250), 0);
  EXPECT_EQ(s.track_frame(600), 350);
  EXPECT_EQ(s.track_frame(749), 499);
  EXPECT_EQ(s.track_frame(750), -1);
  EXPECT_EQ(s.track_frame(12000), -1);  // not looping: silent for good
}

TEST(ShowAudioSchedule, ANegativeOffsetStartsInsideTheTrack) {
  const ShowAudioSchedule s(audio_at(-0.1), false, 10.0, 1000, 500);
  EXPECT_EQ(s.track_frame(0), 100);
  EXPECT_EQ(s.track_frame(399), 499);
  EXPECT_EQ(s.track_frame(400), -1);
}

TEST(ShowAudioSchedule, ALoopingShowRestartsItsTrackOnEveryPass) {
  // 1 s passes, the track starts 0.2 s into each and is 1.5 s long: cut at the wrap.
  const ShowAudioSchedule s(audio_at(0.2), true, 1.0, 1000, 1500);
  EXPECT_EQ(s.track_frame(199), -1);
  EXPECT_EQ(s.track_frame(200), 0);
  EXPECT_EQ(s.track_frame(999), 799);
  EXPECT_EQ(s.track_frame(1000), -1);
  EXPECT_EQ(s.track_frame(1200), 0);
  EXPECT_EQ(s.track_frame(3456), 256);
}

TEST(ShowAudioSchedule, RenderFillsSilenceAroundTheTrack) {
  const ShowAudioSchedule s(audio_at(0.004), false, 1.0, 1000, 3);
  const std::vector<float> track{0.5f, -0.25f, 0.75f};
  std::vector<float> out(8, 9.0f);
  s.render(track, 2, out);
  EXPECT_EQ(out, (std::vector<float>{0.0f, 0.0f, 0.5f, -0.25f, 0.75f, 0.0f, 0.0f, 0.0f}));
}

// A sink that plays nothing (everything written stays queued) and lets the
// test decide how many blocks the player may write.
class RecordingSink final : public AudioSink {
 public:
  struct Shared {
    std::mutex mutex;
    std::condition_variable changed;
    std::vector<std::vector<float>> blocks;
    std::size_t allowed = 0;
  };
  explicit RecordingSink(Shared& shared) : s_(shared) {}
  // The player asks this first in every block, before it reads the clock:
  // the place to hold it.
  std::int64_t queued_frames() override {
    std::unique_lock lock(s_.mutex);
    s_.changed.wait(lock, [&] { return s_.blocks.size() < s_.allowed; });
    std::int64_t n = 0;
    for (const auto& b : s_.blocks) n += static_cast<std::int64_t>(b.size());
    return n;
  }
  void write(std::span<const float> mono) override {
    std::lock_guard lock(s_.mutex);
    s_.blocks.emplace_back(mono.begin(), mono.end());
    s_.changed.notify_all();
  }

 private:
  Shared& s_;
};

void wait_for_blocks(RecordingSink::Shared& shared, std::size_t n) {
  std::unique_lock lock(shared.mutex);
  shared.allowed = n;
  shared.changed.notify_all();
  shared.changed.wait(lock, [&] { return shared.blocks.size() >= n; });
}

TEST(ShowAudioPlayer, PlaysFromTheShowTimeItIsHeardAtAndResyncsAfterAJump) {
  ShowFile show;
  show.duration_s = 10.0;
  show.audio = audio_at(0.52);
  AudioTrack track;
  track.rate = 1000;
  for (int i = 0; i < 3000; ++i) track.samples.push_back(static_cast<float>(i + 1));
  const ShowAudioSchedule schedule(show.audio, false, show.duration_s, 1000, 3000);
  auto expected = [&](std::int64_t first) {
    std::vector<float> out(10);
    schedule.render(track.samples, first, out);
    return out;
  };

  RecordingSink::Shared shared;
  ManualClock clock(from_seconds(100.0));
  {
    ShowAudioPlayer player(show, track, std::make_unique<RecordingSink>(shared), clock);
    // The show started 0.5 s ago: blocks of 10 ms from show time 0.5 s on,
    // silent until the offset (0.52 s), then the track from its start.
    player.start(from_seconds(99.5));
    wait_for_blocks(shared, 3);
    {
      std::lock_guard lock(shared.mutex);
      EXPECT_EQ(shared.blocks[0], expected(500));
      EXPECT_EQ(shared.blocks[1], expected(510));
      EXPECT_EQ(shared.blocks[2], expected(520));
      EXPECT_EQ(shared.blocks[2][0], 1.0f);  // the track's first sample at 0.52 s
    }
    // The clock jumps 1 s (a stalled thread): the next block is the show
    // time heard next (1.5 s + the 30 frames still queued), not a late one.
    clock.set(from_seconds(101.0));
    wait_for_blocks(shared, 4);
    {
      std::lock_guard lock(shared.mutex);
      EXPECT_EQ(shared.blocks[3], expected(1530));
    }
    EXPECT_GE(player.frames_played(), 30);
    player.stop();
    std::lock_guard lock(shared.mutex);
    shared.allowed = SIZE_MAX;  // let the thread leave any write it is in
    shared.changed.notify_all();
  }
}

std::string write_show_with_audio(const std::string& name) {
  const std::string dir = ::testing::TempDir();
  const std::string wav = dir + "/" + name + ".wav";
  SF_INFO info{};
  info.samplerate = 8000;
  info.channels = 2;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* f = sf_open(wav.c_str(), SFM_WRITE, &info);
  std::vector<short> frames(2 * 800);
  for (std::size_t i = 0; i < frames.size(); i += 2) {
    frames[i] = 8000;
    frames[i + 1] = 0;
  }
  sf_writef_short(f, frames.data(), 800);
  sf_close(f);
  const std::string show = dir + "/" + name + ".yaml";
  std::ofstream(show) << "audio: {file: " << name << ".wav, offset_s: 0.5}\n"
                      << "joints:\n  jaw: {keys: [[0, 1]]}\n";
  return show;
}

TEST(ShowAudio, TracksAreMixedDownToOneChannel) {
  const std::string show = write_show_with_audio("stereo");
  const AudioTrack track = load_audio_track(::testing::TempDir() + "/stereo.wav");
  EXPECT_EQ(track.rate, 8000);
  ASSERT_EQ(track.samples.size(), 800u);
  EXPECT_NEAR(track.samples[10], 0.5f * 8000.0f / 32768.0f, 1e-6);
}

TEST(ShowAudio, ATruncatedTrackIsAnErrorNamingTheFile) {
  write_show_with_audio("cut");
  const std::string wav = ::testing::TempDir() + "/cut.wav";
  std::filesystem::resize_file(wav, std::filesystem::file_size(wav) / 2);
  try {
    load_audio_track(wav);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, wav);
    EXPECT_NE(std::string(e.what()).find("truncated WAV file: the data chunk declares 3200 bytes"),
              std::string::npos)
        << e.what();
  }
}

TEST(ShowAudio, WithoutASoundCardTheRunGoesOnAndSaysSoOnce) {
  const std::string with_audio = write_show_with_audio("talk");
  const std::string silent = ::testing::TempDir() + "/silent.yaml";
  std::ofstream(silent) << "joints:\n  jaw: {keys: [[0, 1]]}\n";
  MonotonicClock clock;
  std::vector<std::string> messages;
  int opened = 0;
  auto log = [&](const std::string& m) { messages.push_back(m); };
  auto no_card = [&](int rate) -> std::unique_ptr<AudioSink> {
    ++opened;
    EXPECT_EQ(rate, 8000);
    throw DeviceError("ALSA playback device \"default\": No such file or directory");
  };
  auto players = open_show_audio({with_audio, silent}, false, no_card, clock, log);
  EXPECT_TRUE(players.empty());
  EXPECT_EQ(opened, 1);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0].rfind("audio: cannot play ", 0), 0u) << messages[0];
  EXPECT_NE(messages[0].find("/talk.wav (ALSA playback device \"default\": No such file or "
                             "directory); the show runs without sound"),
            std::string::npos)
      << messages[0];

  // Lockstep: nothing is opened, and that is said once.
  messages.clear();
  opened = 0;
  players = open_show_audio({with_audio, silent}, true, no_card, clock, log);
  EXPECT_TRUE(players.empty());
  EXPECT_EQ(opened, 0);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("not played (a lockstep run is not in real time)"), std::string::npos);
}

TEST(ShowAudio, AnAlsaDeviceThatDoesNotExistIsADeviceErrorNamingIt) {
  try {
    open_alsa_sink("animrt_no_such_pcm", 8000);
    FAIL() << "opened a device that does not exist";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("ALSA playback device \"animrt_no_such_pcm\": "),
              std::string::npos)
        << e.what();
  }
}

// The real ALSA path without a sound card: ALSA's "null" device (part of
// alsa-lib's own configuration) takes the samples and discards them at once,
// so nothing stays queued.
TEST(ShowAudio, TheAlsaSinkWritesToTheNullDevice) {
  std::unique_ptr<AudioSink> sink;
  try {
    sink = open_alsa_sink("null", 8000);
  } catch (const DeviceError& e) {
    FAIL() << "alsa-lib's null device: " << e.what()
           << " (scripts/install-deps.sh installs libasound2)";
  }
  const std::vector<float> block(80, 0.25f);
  for (int i = 0; i < 3; ++i) sink->write(block);
  EXPECT_EQ(sink->queued_frames(), 0);
}

}  // namespace
}  // namespace animrt
