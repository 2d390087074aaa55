// A show's sound track: which track sample sounds at which show time (offset,
// end of track, looping), the player feeding a sink from that schedule once
// the show starts and following the show's pause, seek and play, the run
// handing the show's commands to it, and the no-sound-card path. No sound
// card is needed: the player writes into a sink that records its blocks.

#include "animrt/controllers/show/show_audio.hpp"

#include <gtest/gtest.h>
#include <sndfile.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/show/show_file.hpp"
#include "animrt/controllers/show/show_playhead.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/run_monitor.hpp"
#include "support/sim_rig.hpp"
#include "support/wav_file.hpp"

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

// A sink that plays nothing (everything written stays queued until a
// flush) and lets the test decide how many blocks the player may write.
class RecordingSink final : public AudioSink {
 public:
  struct Shared {
    std::mutex mutex;
    std::condition_variable changed;
    std::vector<std::vector<float>> blocks;
    std::size_t allowed = 0;
    std::size_t flushed_at = 0;        // blocks written before the last flush
    std::vector<std::size_t> flushes;  // the block count at each flush
  };
  explicit RecordingSink(Shared& shared) : s_(shared) {}
  // The player asks this first in every block, before it reads the clock:
  // the place to hold it.
  std::int64_t queued_frames() override {
    std::unique_lock lock(s_.mutex);
    s_.changed.wait(lock, [&] { return s_.blocks.size() < s_.allowed; });
    std::int64_t n = 0;
    for (std::size_t i = s_.flushed_at; i < s_.blocks.size(); ++i) {
      n += static_cast<std::int64_t>(s_.blocks[i].size());
    }
    return n;
  }
  void write(std::span<const float> mono) override {
    std::lock_guard lock(s_.mutex);
    s_.blocks.emplace_back(mono.begin(), mono.end());
    s_.changed.notify_all();
  }
  void flush() override {
    std::lock_guard lock(s_.mutex);
    s_.flushed_at = s_.blocks.size();
    s_.flushes.push_back(s_.blocks.size());
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

// The dashboard's transport, through the player: a pause drops what is
// queued and writes silence while the clock runs on; a seek while paused
// stays silent; play goes on from the sought time; a seek while playing
// jumps there; a play while playing changes nothing.
TEST(ShowAudioPlayer, PauseSilencesItSeekMovesItAndPlayResumesFromThePlayhead) {
  ShowFile show;
  show.duration_s = 10.0;
  show.audio = audio_at(0.0);
  AudioTrack track;
  track.rate = 1000;
  for (int i = 0; i < 9000; ++i) track.samples.push_back(static_cast<float>(i + 1));
  const ShowAudioSchedule schedule(show.audio, false, show.duration_s, 1000, 9000);
  auto expected = [&](std::int64_t first) {
    std::vector<float> out(10);
    schedule.render(track.samples, first, out);
    return out;
  };
  const std::vector<float> silence(10, 0.0f);

  RecordingSink::Shared shared;
  ManualClock clock(from_seconds(100.0));
  {
    ShowAudioPlayer player(show, track, std::make_unique<RecordingSink>(shared), clock);
    const Nanos origin = from_seconds(99.5);  // motion time 0.5 s now
    player.start(origin);
    wait_for_blocks(shared, 2);
    const auto block = [&](std::size_t i) {
      std::lock_guard lock(shared.mutex);
      return shared.blocks.at(i);
    };
    const auto flushes = [&] {
      std::lock_guard lock(shared.mutex);
      return shared.flushes;
    };
    EXPECT_EQ(block(0), expected(500));
    EXPECT_EQ(block(1), expected(510));
    // Pause at motion time 0.5 s: the 20 frames queued go, silence follows,
    // also a second later.
    ASSERT_TRUE(player.control(ShowCommand{false, 0, 0.0}, 0.5));
    wait_for_blocks(shared, 3);
    EXPECT_EQ(block(2), silence);
    EXPECT_EQ(flushes(), (std::vector<std::size_t>{2}));
    clock.set(from_seconds(101.0));
    wait_for_blocks(shared, 4);
    EXPECT_EQ(block(3), silence);
    // Seek to 4 s while paused (at motion time 1.5 s): still silent.
    ASSERT_TRUE(player.control(ShowCommand{false, 1, 4.0}, 1.5));
    wait_for_blocks(shared, 5);
    EXPECT_EQ(block(4), silence);
    // Play at motion time 2 s: the track from show time 4 s on, in step.
    clock.set(from_seconds(101.5));
    ASSERT_TRUE(player.control(ShowCommand{true, 1, 4.0}, 2.0));
    wait_for_blocks(shared, 6);
    EXPECT_EQ(block(5), expected(4000));
    wait_for_blocks(shared, 7);
    EXPECT_EQ(block(6), expected(4010));  // the 10 frames queued since the flush
    EXPECT_EQ(flushes(), (std::vector<std::size_t>{2, 4, 5}));
    // A play while playing moves nothing: no flush, no jump.
    ASSERT_TRUE(player.control(ShowCommand{true, 1, 4.0}, 2.0));
    wait_for_blocks(shared, 8);
    EXPECT_EQ(block(7), expected(4020));
    EXPECT_EQ(flushes().size(), 3u);
    // Seek to 0.25 s while playing (at motion time 2 s): it jumps there.
    ASSERT_TRUE(player.control(ShowCommand{true, 2, 0.25}, 2.0));
    wait_for_blocks(shared, 9);
    EXPECT_EQ(block(8), expected(250));
    EXPECT_EQ(flushes().size(), 4u);
    player.stop();
    std::lock_guard lock(shared.mutex);
    shared.allowed = SIZE_MAX;  // let the thread leave any write it is in
    shared.changed.notify_all();
  }
}

// The run hands a show's commands to its sound track (RunOptions::
// on_show_command) at the motion time the show took them: a playhead fed
// those commands at those times is where the show's own is, after a pause,
// a seek while paused and a play (configs/robots/animatronic.yaml: hello.yaml
// over a gait, lockstep).
TEST(ShowAudio, TheRunHandsTheShowsCommandsToItsSoundTrackAtTheTimesTheyActed) {
  test::SimRig rig(std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml");
  RunMonitor monitor(rig.runner().model());
  RunControls controls;
  struct Taken {
    ShowCommand command;
    double t;
  };
  std::array<Taken, 8> taken{};  // filled in the cycle: no allocation
  std::atomic<int> count{0};
  std::atomic<bool> started{false};
  RunOptions options = rig.options(0.0);
  options.controls = &controls;
  options.monitor = &monitor;
  options.on_motion_start = [&](Nanos) { started = true; };
  options.on_show_command = [&](const ShowCommand& command, double t) {
    const int i = count.load();
    if (i < static_cast<int>(taken.size())) taken[static_cast<std::size_t>(i)] = {command, t};
    count = i + 1;
  };
  RunSummary summary;
  std::thread run([&] { summary = rig.run(options); });
  const auto wait = [&](const std::function<bool()>& done) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!done() && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return done();
  };
  ASSERT_TRUE(wait([&] { return started.load(); }));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  controls.show.post(ShowCommand{false, 0, 0.0});  // pause
  EXPECT_TRUE(wait([&] { return count == 1; }));
  controls.show.post(ShowCommand{false, 1, 2.5});  // seek while paused
  EXPECT_TRUE(wait([&] { return count == 2; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  controls.show.post(ShowCommand{true, 1, 2.5});  // play
  EXPECT_TRUE(wait([&] { return count == 3; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  controls.stop = true;
  run.join();
  ASSERT_EQ(count, 3);
  EXPECT_FALSE(taken[0].command.playing);
  EXPECT_EQ(taken[1].command.seeks, 1u);
  EXPECT_TRUE(taken[2].command.playing);
  EXPECT_LT(taken[0].t, taken[1].t);
  EXPECT_LT(taken[1].t, taken[2].t);

  // The show's playhead as the run last published it (the end of the
  // motion), and the sound track's, fed the same commands.
  RunView view;
  monitor.read(view);
  ASSERT_TRUE(view.show.show);
  ShowPlayhead playhead(view.show.duration_s, true);  // hello.yaml loops
  for (int i = 0; i < 3; ++i) playhead.control(taken[i].command, taken[i].t);
  const ShowPosition sound = playhead.position(view.motion_time_s);
  EXPECT_NEAR(sound.position_s, view.show.position_s, 1e-9);
  EXPECT_GT(view.motion_time_s, taken[2].t);
  EXPECT_NEAR(sound.position_s,
              std::fmod(2.5 + (view.motion_time_s - taken[2].t), view.show.duration_s), 1e-9);
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

// The show file's check (validate, and every command that loads the show)
// finds the cut track at the show's line, as loading the track does.
TEST(ShowAudio, ATruncatedTrackIsRefusedWhereTheShowNamesIt) {
  const std::string show = write_show_with_audio("cut_show");
  const std::string wav = ::testing::TempDir() + "/cut_show.wav";
  EXPECT_NO_THROW(load_show_file(show));
  std::filesystem::resize_file(wav, std::filesystem::file_size(wav) - 10);
  try {
    (void)load_show_file(show);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              show + ":1:15: audio.file: audio file \"" +
                  (std::filesystem::path(show).parent_path() / "cut_show.wav").string() +
                  "\": truncated WAV file: the data chunk declares 3200 "
                  "bytes but only 3190 are present");
  }
}

// A float track with a NaN or an infinite sample: validate (and every
// command that loads the show) refuses it at the show's line, as the run's
// loader of the track does, with the sample's problem.
TEST(ShowAudio, ATrackWithANonFiniteSampleIsRefusedWhereTheShowNamesIt) {
  const std::string dir = ::testing::TempDir();
  for (const float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    std::vector<float> samples(800, 0.25f);
    samples[100] = bad;
    ASSERT_TRUE(write_float_wav(dir + "/nan_show.wav", samples, 8000));
    const std::string show = dir + "/nan_show.yaml";
    std::ofstream(show) << "audio: {file: nan_show.wav}\n"
                        << "joints:\n  jaw: {keys: [[0, 1]]}\n";
    try {
      (void)load_show_file(show);
      FAIL() << "expected an InputError for " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()),
                show + ":1:15: audio.file: audio file \"" +
                    (std::filesystem::path(show).parent_path() / "nan_show.wav").string() +
                    "\": sample 100 (at 0.0125 s) is not a finite number (NaN or infinity)");
    }
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
  // A pause or a seek drops what is queued; writing goes on after it.
  sink->flush();
  EXPECT_EQ(sink->queued_frames(), 0);
  sink->write(block);
}

}  // namespace
}  // namespace animrt
