// Feetech SCS/STS codec against the example packets printed in Feetech's
// "Serial Bus Smart Servo Communication Protocol Manual" (section 1.3,
// examples 1-9) and the STS3215 memory table's instruction examples. Every
// instruction the codec encodes is checked against a printed packet.

#include "animrt/bridge/feetech/feetech_codec.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

namespace animrt::ft {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Example 1: Ping of ID 1, and its status packet.
const Bytes kPingId1 = {0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB};
const Bytes kEmptyStatusId1 = {0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC};
// Example 2: Read 2 bytes at 0x38 (present position) of ID 1; the answer is
// 0x0518 = 1304, low byte first (STS).
const Bytes kReadPositionId1 = {0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE};
const Bytes kReadPositionStatusId1 = {0xFF, 0xFF, 0x01, 0x04, 0x00, 0x18, 0x05, 0xDD};
// Example 3: broadcast Write of ID = 1 (address 5).
const Bytes kWriteIdBroadcast = {0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x05, 0x01, 0xF4};
// Example 4: Write of position 2048, time 0, speed 1000 at 0x2A to ID 1.
const Bytes kWriteGoalId1 = {0xFF, 0xFF, 0x01, 0x09, 0x03, 0x2A, 0x00,
                             0x08, 0x00, 0x00, 0xE8, 0x03, 0xD5};
// Example 5: the same as Reg Write, for ID 1 and ID 10.
const Bytes kRegWriteGoalId1 = {0xFF, 0xFF, 0x01, 0x09, 0x04, 0x2A, 0x00,
                                0x08, 0x00, 0x00, 0xE8, 0x03, 0xD4};
const Bytes kRegWriteGoalId10 = {0xFF, 0xFF, 0x0A, 0x09, 0x04, 0x2A, 0x00,
                                 0x08, 0x00, 0x00, 0xE8, 0x03, 0xCB};
// Example 6: broadcast Action.
const Bytes kActionBroadcast = {0xFF, 0xFF, 0xFE, 0x02, 0x05, 0xFA};
// Example 7: Sync Write of that block to IDs 1..4.
const Bytes kSyncWriteIds1to4 = {0xFF, 0xFF, 0xFE, 0x20, 0x83, 0x2A, 0x06, 0x01, 0x00,
                                 0x08, 0x00, 0x00, 0xE8, 0x03, 0x02, 0x00, 0x08, 0x00,
                                 0x00, 0xE8, 0x03, 0x03, 0x00, 0x08, 0x00, 0x00, 0xE8,
                                 0x03, 0x04, 0x00, 0x08, 0x00, 0x00, 0xE8, 0x03, 0x58};
// Example 8: Sync Read of 8 bytes at 0x38 from IDs 1 and 2, and the two
// status packets (ID 1 at 2048, ID 2 at 2047).
const Bytes kSyncReadIds12 = {0xFF, 0xFF, 0xFE, 0x06, 0x82, 0x38, 0x08, 0x01, 0x02, 0x36};
const Bytes kSyncReadStatusId1 = {0xFF, 0xFF, 0x01, 0x0A, 0x00, 0x00, 0x08,
                                  0x00, 0x00, 0x00, 0x00, 0x79, 0x1E, 0x55};
const Bytes kSyncReadStatusId2 = {0xFF, 0xFF, 0x02, 0x0A, 0x00, 0xFF, 0x07,
                                  0x00, 0x00, 0x00, 0x00, 0x77, 0x23, 0x53};
// Example 9: Reset of ID 1.
const Bytes kResetId1 = {0xFF, 0xFF, 0x01, 0x02, 0x06, 0xF6};
// STS3215 memory table examples: broadcast write of 0 to the lock flag (55),
// and ID 1 -> 2.
const Bytes kUnlockBroadcast = {0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x37, 0x00, 0xC3};
const Bytes kChangeId1To2 = {0xFF, 0xFF, 0x01, 0x04, 0x03, 0x05, 0x02, 0xF0};

Bytes encoded(std::size_t n, const std::array<std::uint8_t, kMaxPacket>& buf) {
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

Bytes goal_block() {
  Bytes b(6);
  put_u16(Series::sts, &b[0], 2048);
  put_u16(Series::sts, &b[2], 0);
  put_u16(Series::sts, &b[4], 1000);
  return b;
}

TEST(FeetechCodec, EncodesEveryInstructionAsTheManualPrintsIt) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  EXPECT_EQ(encoded(encode_ping(1, buf), buf), kPingId1);
  EXPECT_EQ(encoded(encode_read(1, reg::present_position, 2, buf), buf), kReadPositionId1);
  const std::uint8_t one = 1;
  EXPECT_EQ(encoded(encode_write(kBroadcastId, reg::id, {&one, 1}, buf), buf), kWriteIdBroadcast);
  const Bytes block = goal_block();
  EXPECT_EQ(encoded(encode_write(1, reg::goal_position, block, buf), buf), kWriteGoalId1);
  EXPECT_EQ(encoded(encode_reg_write(1, reg::goal_position, block, buf), buf), kRegWriteGoalId1);
  EXPECT_EQ(encoded(encode_reg_write(10, reg::goal_position, block, buf), buf), kRegWriteGoalId10);
  EXPECT_EQ(encoded(encode_action(kBroadcastId, buf), buf), kActionBroadcast);
  const std::uint8_t ids[] = {1, 2, 3, 4};
  Bytes data;
  for (int i = 0; i < 4; ++i) data.insert(data.end(), block.begin(), block.end());
  EXPECT_EQ(encoded(encode_sync_write(reg::goal_position, 6, ids, data, buf), buf),
            kSyncWriteIds1to4);
  const std::uint8_t ids12[] = {1, 2};
  EXPECT_EQ(encoded(encode_sync_read(reg::present_position, 8, ids12, buf), buf), kSyncReadIds12);
  EXPECT_EQ(encoded(encode_packet(1, inst::reset, {}, buf), buf), kResetId1);
  const std::uint8_t zero = 0, two = 2;
  EXPECT_EQ(encoded(encode_write(kBroadcastId, reg::sts_lock, {&zero, 1}, buf), buf),
            kUnlockBroadcast);
  EXPECT_EQ(encoded(encode_write(1, reg::id, {&two, 1}, buf), buf), kChangeId1To2);
  EXPECT_EQ(encoded(encode_status(1, 0, {}, buf), buf), kEmptyStatusId1);
  const std::uint8_t position[] = {0x18, 0x05};
  EXPECT_EQ(encoded(encode_status(1, 0, position, buf), buf), kReadPositionStatusId1);
}

TEST(FeetechCodec, DecodesTheManualsStatusPackets) {
  Decoder d;
  Bytes stream = kReadPositionStatusId1;
  stream.insert(stream.end(), kSyncReadStatusId1.begin(), kSyncReadStatusId1.end());
  stream.insert(stream.end(), kSyncReadStatusId2.begin(), kSyncReadStatusId2.end());
  d.feed(stream);
  Packet p;
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.id, 1);
  EXPECT_EQ(p.code, 0);  // error byte
  ASSERT_EQ(p.params.size(), 2u);
  EXPECT_EQ(get_u16(Series::sts, p.params.data()), 1304);
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  ASSERT_EQ(p.params.size(), 8u);
  EXPECT_EQ(get_u16(Series::sts, p.params.data()), 2048);
  EXPECT_EQ(p.params[6], 0x79);
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.id, 2);
  EXPECT_EQ(get_u16(Series::sts, p.params.data()), 2047);
  EXPECT_EQ(p.raw.size(), kSyncReadStatusId2.size());
  EXPECT_EQ(d.next(p), DecodeResult::need_more);
}

TEST(FeetechCodec, DecodesInstructionPacketsByteByByte) {
  Decoder d;
  Packet p;
  for (std::size_t i = 0; i + 1 < kSyncWriteIds1to4.size(); ++i) {
    d.feed({&kSyncWriteIds1to4[i], 1});
    ASSERT_EQ(d.next(p), DecodeResult::need_more) << i;
  }
  d.feed({&kSyncWriteIds1to4.back(), 1});
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.id, kBroadcastId);
  EXPECT_EQ(p.code, inst::sync_write);
  EXPECT_EQ(p.params.size(), 2u + 4u * 7u);
  EXPECT_EQ(p.params[0], reg::goal_position);
}

TEST(FeetechCodec, BadChecksumIsDroppedAndTheNextPacketStillFound) {
  Bytes bad = kWriteGoalId1;
  bad.back() ^= 0x01;
  Bytes stream = {0x00, 0x13};  // junk before
  stream.insert(stream.end(), bad.begin(), bad.end());
  stream.insert(stream.end(), kPingId1.begin(), kPingId1.end());
  Decoder d;
  d.feed(stream);
  Packet p;
  EXPECT_EQ(d.next(p), DecodeResult::bad_checksum);
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.code, inst::ping);
  EXPECT_EQ(p.id, 1);
  EXPECT_GE(d.stray_bytes(), 2u);
}

TEST(FeetechCodec, IdleFfBytesBeforeAHeaderAreSkipped) {
  Bytes stream = {0xFF, 0xFF, 0xFF};
  stream.insert(stream.end(), kActionBroadcast.begin(), kActionBroadcast.end());
  Decoder d;
  d.feed(stream);
  Packet p;
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.id, kBroadcastId);
  EXPECT_EQ(p.code, inst::action);
}

TEST(FeetechCodec, ImpossibleLengthIsMalformed) {
  const Bytes stream = {0xFF, 0xFF, 0x01, 0x01, 0x00};
  Decoder d;
  d.feed(stream);
  Packet p;
  EXPECT_EQ(d.next(p), DecodeResult::malformed);
}

TEST(FeetechCodec, ByteOrderDiffersBetweenSeries) {
  std::uint8_t b[2];
  put_u16(Series::sts, b, 0x0518);
  EXPECT_EQ(b[0], 0x18);
  EXPECT_EQ(b[1], 0x05);
  put_u16(Series::scs, b, 0x0518);
  EXPECT_EQ(b[0], 0x05);
  EXPECT_EQ(b[1], 0x18);
  EXPECT_EQ(get_u16(Series::scs, b), 0x0518);
}

TEST(FeetechCodec, NegativeValuesRoundTripThroughTheSignBit) {
  // STS: bit 15 is the direction, the magnitude below it.
  EXPECT_EQ(encode_signed(-1, kStsSignBit), 0x8001);
  EXPECT_EQ(encode_signed(-2048, kStsSignBit), 0x8800);
  EXPECT_EQ(encode_signed(2048, kStsSignBit), 0x0800);
  EXPECT_EQ(decode_signed(0x8800, kStsSignBit), -2048);
  // SCS loads and PWM: bit 10.
  EXPECT_EQ(encode_signed(-100, kScsSignBit), 0x0464);
  EXPECT_EQ(decode_signed(0x0464, kScsSignBit), -100);
  for (int bit : {kStsSignBit, kScsSignBit}) {
    const std::int32_t max = (1 << bit) - 1;
    for (std::int32_t v : {-max, -1000 % max, -1, 0, 1, 517 % max, max}) {
      EXPECT_EQ(decode_signed(encode_signed(v, bit), bit), v) << "bit " << bit << " v " << v;
    }
    // Beyond the magnitude: clamped, never wrapped into the sign bit.
    EXPECT_EQ(decode_signed(encode_signed(max + 5, bit), bit), max);
    EXPECT_EQ(decode_signed(encode_signed(-max - 5, bit), bit), -max);
  }
  // Through the wire bytes, both byte orders.
  for (Series s : {Series::sts, Series::scs}) {
    std::uint8_t b[2];
    put_u16(s, b, encode_signed(-1234, kStsSignBit));
    EXPECT_EQ(decode_signed(get_u16(s, b), kStsSignBit), -1234);
  }
}

TEST(FeetechCodec, RefusesPacketsThatDoNotFit) {
  std::array<std::uint8_t, 5> small{};
  EXPECT_EQ(encode_ping(1, small), 0u);
  std::array<std::uint8_t, kMaxPacket> buf{};
  std::vector<std::uint8_t> big(300, 0);
  EXPECT_EQ(encode_write(1, 0, big, buf), 0u);
  const std::uint8_t ids[] = {1, 2};
  const std::uint8_t data[3] = {};
  EXPECT_EQ(encode_sync_write(42, 2, ids, data, buf), 0u);  // 3 bytes for 2 x 2
}

}  // namespace
}  // namespace animrt::ft
