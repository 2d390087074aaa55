// An LTC signal that jumps, written into a WAV by libltc's encoder and read
// by the receiver as a capture device delivers it: after the jump the cue
// that should be playing is asked for at the time into it that the
// timecode says. The times asserted are the signal's, not the wall's.

#include <gtest/gtest.h>
#include <ltc.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/runtime/ltc_receiver.hpp"

namespace animrt {
namespace {

// `count` frames of 25 fps LTC from MM:SS at 48 kHz, appended to `out`.
void ltc_frames(int mins, int secs, int count, head::Audio& out) {
  LTCEncoder* e = ltc_encoder_create(48000, 25, LTC_TV_625_50, 0);
  SMPTETimecode tc{};
  tc.mins = static_cast<unsigned char>(mins);
  tc.secs = static_cast<unsigned char>(secs);
  ltc_encoder_set_timecode(e, &tc);
  for (int i = 0; i < count; ++i) {
    ltc_encoder_encode_frame(e);
    ltcsnd_sample_t* buf = nullptr;
    const int n = ltc_encoder_get_bufferptr(e, &buf, 1);
    for (int k = 0; k < n; ++k)
      out.samples.push_back((static_cast<float>(buf[k]) - 128.0f) / 160.0f);
    ltc_encoder_inc_timecode(e);
  }
  ltc_encoder_free(e);
}

// One 25 fps frame showing HH:MM:SS:FF as written, whatever a clock shows.
void ltc_frame_showing(int hours, int mins, int secs, int frame, head::Audio& out) {
  LTCEncoder* e = ltc_encoder_create(48000, 25, LTC_TV_625_50, 0);
  SMPTETimecode tc{};
  tc.hours = static_cast<unsigned char>(hours);
  tc.mins = static_cast<unsigned char>(mins);
  tc.secs = static_cast<unsigned char>(secs);
  tc.frame = static_cast<unsigned char>(frame);
  ltc_encoder_set_timecode(e, &tc);
  ltc_encoder_encode_frame(e);
  ltcsnd_sample_t* buf = nullptr;
  const int n = ltc_encoder_get_bufferptr(e, &buf, 1);
  for (int k = 0; k < n; ++k) out.samples.push_back((static_cast<float>(buf[k]) - 128.0f) / 160.0f);
  ltc_encoder_free(e);
}

// Frames whose time no clock shows (hour 25, frame 27 at 25 fps: a misset
// generator, noise) are counted and dropped: they neither jump the chase
// nor ask for a cue (hour 25 asked for the last cue of the day).
TEST(LtcSeek, AFrameNoClockShowsIsDroppedAndCounted) {
  const auto wav = std::filesystem::temp_directory_path() /
                   ("animrt_ltc_bad_" + std::to_string(::getpid()) + ".wav");
  head::Audio signal;
  signal.sample_rate = 48000;
  ltc_frames(0, 0, 15, signal);  // 00:00:00:00 .. 00:00:00:14
  for (int i = 0; i < 5; ++i) ltc_frame_showing(25, 0, 0, i, signal);
  for (int i = 0; i < 5; ++i) ltc_frame_showing(0, 0, 9, 25 + i % 3, signal);
  // On where it would be: 00:00:01:00 .. 05 (the last is decoded only when
  // the next begins: one more).
  ltc_frames(0, 1, 6, signal);
  head::write_wav(wav.string(), signal);
  std::mutex mutex;
  std::vector<int> asked;
  {
    LtcReceiver ltc(wav.string(), 25, 0.5, {{0.2, 1}, {9.5, 2}, {80000.0, 3}},
                    [&](int cue, double) {
                      std::lock_guard lock(mutex);
                      asked.push_back(cue);
                    });
    ltc.begin();
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (ltc.frames() + ltc.malformed() < 30 && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_EQ(ltc.malformed(), 10u);
    EXPECT_EQ(ltc.frames(), 20u);
    EXPECT_EQ(ltc.jumps(), 0u);
  }
  std::filesystem::remove(wav);
  std::lock_guard lock(mutex);
  EXPECT_EQ(asked, std::vector<int>{1});
}

TEST(LtcSeek, AfterAJumpTheCueIsAskedForAtTheTimeIntoItThatTheTimecodeSays) {
  const auto wav = std::filesystem::temp_directory_path() /
                   ("animrt_ltc_seek_" + std::to_string(::getpid()) + ".wav");
  head::Audio signal;
  signal.sample_rate = 48000;
  ltc_frames(0, 0, 15, signal);   // 0.6 s from 00:00:00:00
  ltc_frames(10, 0, 15, signal);  // cued to 00:10:00:00
  head::write_wav(wav.string(), signal);

  std::mutex mutex;
  std::vector<std::pair<int, double>> asked;
  {
    LtcReceiver ltc(wav.string(), 25, 0.5, {{0.2, 1}, {599.0, 2}}, [&](int cue, double at_s) {
      std::lock_guard lock(mutex);
      asked.emplace_back(cue, at_s);
    });
    ltc.begin();
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (ltc.cues_asked() < 2 && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_EQ(ltc.jumps(), 1u);
  }
  std::filesystem::remove(wav);
  std::lock_guard lock(mutex);
  ASSERT_EQ(asked.size(), 2u);
  // Cue 1 as the timecode crossed 0.2 s: at most a block and a frame past it.
  EXPECT_EQ(asked[0].first, 1);
  EXPECT_GE(asked[0].second, 0.0);
  EXPECT_LT(asked[0].second, 0.1);
  // Cue 2 began at 00:09:59:00: the first frame after the jump puts it 1 s
  // (plus that frame and the block it was read in) into it.
  EXPECT_EQ(asked[1].first, 2);
  EXPECT_GE(asked[1].second, 1.0);
  EXPECT_LT(asked[1].second, 1.15);
}

}  // namespace
}  // namespace animrt
