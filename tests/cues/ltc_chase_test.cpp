// Chasing LTC timecode on given times: cues come as the timecode crosses
// their starts, a jump re-syncs to the cue that should be playing, a dropout
// freewheels then loses the timecode, and a timecode string is checked.

#include "animrt/runtime/ltc_chase.hpp"

#include <gtest/gtest.h>

namespace animrt {
namespace {

constexpr double kLtcFrame = 1.0 / 25;

// Frames from timecode `tc` at input time `at`, `count` of them, advancing
// after each; the cues asked for, in order.
std::vector<int> ltc_play(LtcChase& chase, double tc, double at, int count) {
  std::vector<int> asked;
  for (int i = 0; i < count; ++i) {
    chase.frame(tc + i * kLtcFrame, at + (i + 1) * kLtcFrame);
    const int cue = chase.advance(at + (i + 1) * kLtcFrame);
    if (cue >= 0) asked.push_back(cue);
  }
  return asked;
}

TEST(LtcChase, CuesComeAsTheTimecodeCrossesThemAndAJumpReSyncs) {
  LtcChase chase(25, 0.5, {{0.4, 1}, {599.0, 2}, {600.8, 3}, {1200.0, 4}});
  EXPECT_EQ(ltc_play(chase, 0.0, 0.0, 25), std::vector<int>{1});
  EXPECT_NEAR(*chase.timecode(), 1.0, 1e-9);
  // Cued to ten minutes: the cue that should be playing there.
  EXPECT_EQ(ltc_play(chase, 600.0, 1.0, 15), std::vector<int>{2});
  EXPECT_EQ(chase.jumps(), 1u);
  // Silence: freewheels through 600.8 (cue 3), then frames where expected.
  std::vector<int> asked;
  for (int i = 1; i <= 10; ++i) {
    const int cue = chase.advance(1.6 + i * kLtcFrame);
    if (cue >= 0) asked.push_back(cue);
  }
  EXPECT_EQ(asked, std::vector<int>{3});
  EXPECT_EQ(chase.dropouts(), 1u);
  EXPECT_TRUE(ltc_play(chase, 601.0, 2.0, 10).empty());
  EXPECT_EQ(chase.jumps(), 1u);
  // The signal ends: a dropout, and after freewheel_s the timecode is lost.
  EXPECT_EQ(chase.advance(2.4 + 0.3), -1);
  EXPECT_TRUE(chase.timecode().has_value());
  EXPECT_EQ(chase.advance(2.4 + 0.6), -1);
  EXPECT_FALSE(chase.timecode().has_value());
  EXPECT_EQ(chase.dropouts(), 2u);
  EXPECT_EQ(chase.losses(), 1u);
  // A lock regained at a new time re-syncs without counting a jump.
  EXPECT_EQ(ltc_play(chase, 1300.0, 5.0, 3), std::vector<int>{4});
  EXPECT_EQ(chase.jumps(), 1u);
  EXPECT_EQ(chase.frames(), 53u);
}

// Time-of-day timecode runs past midnight into the next day: no jump, and
// the cues on either side of midnight come as it crosses them.
TEST(LtcChase, MidnightIsNoJump) {
  const double day = 24 * 3600.0;
  LtcChase chase(25, 0.5, {{0.0, 1}, {0.2, 2}, {day - 0.2, 3}});
  // Locked at 23:59:59:15: cue 2 is the one playing (since 00:00:00:05);
  // cue 3 as the timecode crosses 23:59:59:20.
  EXPECT_EQ(ltc_play(chase, day - 0.4, 0.0, 5), (std::vector<int>{2, 3}));
  std::vector<int> asked = ltc_play(chase, day - 0.2, 0.2, 5);   // 23:59:59:20 .. 24
  const std::vector<int> after = ltc_play(chase, 0.0, 0.4, 10);  // 00:00:00:00 ..
  asked.insert(asked.end(), after.begin(), after.end());
  EXPECT_EQ(asked, (std::vector<int>{1, 2}));
  EXPECT_EQ(chase.jumps(), 0u);
  EXPECT_NEAR(*chase.timecode(), 0.4, 1e-9);
  // Cue 2 was asked for as the timecode crossed 0.2 s: a frame past it at most.
  EXPECT_GE(chase.cue_offset(), 0.0);
}

TEST(LtcChase, TimecodesAreCheckedAgainstTheFrameRate) {
  EXPECT_DOUBLE_EQ(*parse_timecode("01:02:03:12", 25), 3723.48);
  EXPECT_DOUBLE_EQ(*parse_timecode("00:00:01;29", 30), 1.0 + 29.0 / 30);
  EXPECT_FALSE(parse_timecode("00:00:00:25", 25));
  EXPECT_FALSE(parse_timecode("24:00:00:00", 25));
  EXPECT_FALSE(parse_timecode("00:60:00:00", 25));
  EXPECT_FALSE(parse_timecode("00:00:00", 25));
  EXPECT_FALSE(parse_timecode("00:00:00:00x", 25));
}

}  // namespace
}  // namespace animrt
