// The BNO08x UART-RVC codec against the example message of the BNO080
// datasheet (1000-3927, 1.3.5.2 "UART-RVC protocol"), and the host's stream
// parser against what a real line does: a start mid-frame, noise, a
// corrupted byte, a lost frame.

#include "animrt/bridge/imu/bno08x_rvc.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace animrt::imu {
namespace {

// Datasheet: index 222, yaw 0.01 deg, pitch -1.10 deg, roll 20.85 deg,
// acceleration -371, -20, 977 mg, checksum 0xE7.
const RvcBytes kDatasheetMessage = {0xAA, 0xAA, 0xDE, 0x01, 0x00, 0x92, 0xFF, 0x25, 0x08, 0x8D,
                                    0xFE, 0xEC, 0xFF, 0xD1, 0x03, 0x00, 0x00, 0x00, 0xE7};

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(Bno08xRvc, DecodesTheDatasheetMessage) {
  const auto frame = decode_rvc(kDatasheetMessage);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->index, 222);
  EXPECT_EQ(frame->yaw_cdeg, 1);
  EXPECT_EQ(frame->pitch_cdeg, -110);
  EXPECT_EQ(frame->roll_cdeg, 2085);
  EXPECT_EQ(frame->accel_mg[0], -371);
  EXPECT_EQ(frame->accel_mg[1], -20);
  EXPECT_EQ(frame->accel_mg[2], 977);
  // In SI, as the datasheet converts them (-3.638, -0.196, 9.581 m/s^2).
  const ImuReading r = rvc_reading(*frame, 0.0);
  EXPECT_NEAR(r.accel_m_s2[0], -3.638, 5e-4);
  EXPECT_NEAR(r.accel_m_s2[1], -0.196, 5e-4);
  EXPECT_NEAR(r.accel_m_s2[2], 9.581, 5e-4);
  EXPECT_NEAR(yaw_of(r.quat), 0.01 * kDeg, 1e-9);
  EXPECT_NEAR(pitch_of(r.quat), -1.10 * kDeg, 1e-9);
  EXPECT_NEAR(roll_of(r.quat), 20.85 * kDeg, 1e-9);
}

TEST(Bno08xRvc, EncodesTheDatasheetMessage) {
  RvcFrame f;
  f.index = 0xDE;
  f.yaw_cdeg = 1;
  f.pitch_cdeg = -110;
  f.roll_cdeg = 2085;
  f.accel_mg = {-371, -20, 977};
  EXPECT_EQ(encode_rvc(f), kDatasheetMessage);
  // And from the attitude in SI, as the simulated part builds it.
  const auto q = quat_from_ypr(0.01 * kDeg, -1.10 * kDeg, 20.85 * kDeg);
  const RvcFrame g = rvc_frame(0xDE, q, {-371 * 9.80665e-3, -20 * 9.80665e-3, 977 * 9.80665e-3});
  EXPECT_EQ(encode_rvc(g), kDatasheetMessage);
}

TEST(Bno08xRvc, RefusesABadChecksumOrHeader) {
  RvcBytes bad = kDatasheetMessage;
  bad[18] ^= 0x01;
  EXPECT_FALSE(decode_rvc(bad));
  bad = kDatasheetMessage;
  bad[1] = 0xAB;
  EXPECT_FALSE(decode_rvc(bad));
}

TEST(Bno08xRvc, StreamResynchronisesAndCountsWhatItLost) {
  RvcStream stream;
  std::vector<std::uint8_t> line;
  // Opened mid-frame: the tail of a frame first.
  line.insert(line.end(), kDatasheetMessage.begin() + 7, kDatasheetMessage.end());
  RvcFrame f;
  f.index = 10;
  f.roll_cdeg = 100;
  const auto a = encode_rvc(f);
  line.insert(line.end(), a.begin(), a.end());
  // A frame with a corrupted byte, then frame 13 (12 never arrived).
  f.index = 11;
  auto b = encode_rvc(f);
  b[8] ^= 0x40;
  line.insert(line.end(), b.begin(), b.end());
  f.index = 13;
  f.roll_cdeg = 200;
  const auto c = encode_rvc(f);
  line.insert(line.end(), c.begin(), c.end());
  // Fed in uneven pieces, as reads return them.
  std::size_t frames = 0;
  for (std::size_t i = 0; i < line.size(); i += 7) {
    frames += stream.feed(std::span(line).subspan(i, std::min<std::size_t>(7, line.size() - i)));
  }
  EXPECT_EQ(frames, 2u);
  EXPECT_EQ(stream.frames(), 2u);
  EXPECT_EQ(stream.latest().index, 13);
  EXPECT_EQ(stream.latest().roll_cdeg, 200);
  EXPECT_GE(stream.checksum_errors(), 1u);
  EXPECT_EQ(stream.lost_frames(), 2u);  // 11 (corrupted) and 12
  EXPECT_GT(stream.skipped_bytes(), 0u);
}

TEST(Bno08xRvc, RoundTripsAnAttitudeToItsResolution) {
  const auto q = quat_from_ypr(1.2, -0.4, 2.9);
  const RvcFrame f = rvc_frame(0, q, {0.0, 0.0, 9.80665});
  const ImuReading r = rvc_reading(*decode_rvc(encode_rvc(f)), 0.0);
  EXPECT_NEAR(yaw_of(r.quat), 1.2, 0.005 * kDeg);
  EXPECT_NEAR(pitch_of(r.quat), -0.4, 0.005 * kDeg);
  EXPECT_NEAR(roll_of(r.quat), 2.9, 0.005 * kDeg);
  EXPECT_EQ(f.accel_mg[2], 1000);
}

}  // namespace
}  // namespace animrt::imu
