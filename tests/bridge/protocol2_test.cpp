// Dynamixel Protocol 2.0 codec against the example packets of the ROBOTIS
// e-manual, "DYNAMIXEL Protocol 2.0" (https://emanual.robotis.com/docs/en/dxl/protocol2/,
// source docs/en/dxl/protocol2.md in github.com/ROBOTIS-GIT/emanual). Vectors
// marked "computed" are not printed in the manual; they were built from the
// spec and cross-checked with an independent bit-by-bit CRC in Python.

#include "animrt/bridge/dynamixel/protocol2.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "bridge/encoded.hpp"

namespace animrt::dxl {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Manual, Ping, Example 1: ping of ID 1 ...
const Bytes kPingId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E};
// ... and the status packet of ID 1 (XM430-W210, model 1030, firmware 38).
const Bytes kPingStatusId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00,
                              0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D};
// Manual, Ping, Example 2: broadcast ping, and the status packet of ID 2.
const Bytes kPingBroadcast = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42};
const Bytes kPingStatusId2 = {0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x07, 0x00,
                              0x55, 0x00, 0x06, 0x04, 0x26, 0x6F, 0x6D};
// Manual, Read, Example: Present Position (132, 4 bytes) of ID 1 = 166.
const Bytes kReadId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00,
                        0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15};
const Bytes kReadStatusId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55,
                              0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0};
// Manual, Write, Example: 512 to Goal Position (116, 4 bytes) of ID 1, and
// the (empty) status packet.
const Bytes kWriteId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x09, 0x00, 0x03,
                         0x74, 0x00, 0x00, 0x02, 0x00, 0x00, 0xCA, 0x89};
const Bytes kEmptyStatusId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C};
// Manual, Sync Read, Example: Present Position of IDs 1 and 2 (ID 1 answers
// kReadStatusId1, ID 2 answers 2079).
const Bytes kSyncReadIds12 = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x09, 0x00, 0x82,
                              0x84, 0x00, 0x04, 0x00, 0x01, 0x02, 0xCE, 0xFA};
const Bytes kSyncReadStatusId2 = {0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x08, 0x00, 0x55,
                                  0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE};
// Manual, Sync Write, Example: Goal Position 150 to ID 1 and 170 to ID 2.
const Bytes kSyncWriteIds12 = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x11, 0x00, 0x83,
                               0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00, 0x00,
                               0x00, 0x02, 0xAA, 0x00, 0x00, 0x00, 0x82, 0x87};
// Manual, Reboot, Example: reboot of ID 1.
const Bytes kRebootId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x08, 0x2F, 0x4E};
// Manual, Bulk Read, Example: status packet of ID 2 (Present Temperature 36).
const Bytes kBulkReadStatusId2 = {0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x05,
                                  0x00, 0x55, 0x00, 0x24, 0x8B, 0xA9};

// Computed (no stuffing example in the manual): Write of FF FF FD 00 to Goal
// Position of ID 1. The params FF FF FD get an extra FD; LEN counts it (0x0A).
const Bytes kStuffedWriteId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x0A, 0x00, 0x03, 0x74,
                                0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0x00, 0x21, 0xE7};
// Computed: status of ID 1 with the alert bit and Access Error (0x80 | 7).
const Bytes kAlertAccessStatusId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x04,
                                     0x00, 0x55, 0x87, 0xB3, 0x0F};

// Feeds everything and collects results until need_more.
struct Drained {
  std::vector<DecodeResult> results;
  std::vector<Packet> packets;  // spans are copied below
  std::vector<Bytes> params;
};

Drained drain(Decoder& d) {
  Drained out;
  Packet p;
  for (;;) {
    const DecodeResult r = d.next(p);
    if (r == DecodeResult::need_more) break;
    out.results.push_back(r);
    if (r == DecodeResult::packet) {
      out.packets.push_back(p);
      out.params.emplace_back(p.params.begin(), p.params.end());
    }
  }
  return out;
}

Drained decode_all(const Bytes& bytes) {
  Decoder d;
  EXPECT_EQ(d.feed(bytes), bytes.size());
  return drain(d);
}

TEST(Protocol2Crc, ManualPacketsCarryTheirCrc) {
  for (const Bytes* p : {&kPingId1, &kPingStatusId1, &kPingBroadcast, &kPingStatusId2, &kReadId1,
                         &kReadStatusId1, &kWriteId1, &kEmptyStatusId1, &kSyncReadIds12,
                         &kSyncReadStatusId2, &kSyncWriteIds12, &kRebootId1, &kBulkReadStatusId2}) {
    const std::size_t n = p->size() - 2;
    const std::uint16_t expected = get_u16(p->data() + n);
    EXPECT_EQ(crc16({p->data(), n}), expected);
  }
}

TEST(Protocol2Crc, AccumulatesAcrossCalls) {
  const std::size_t n = kSyncWriteIds12.size() - 2;
  const std::span<const std::uint8_t> all(kSyncWriteIds12.data(), n);
  EXPECT_EQ(crc16(all.subspan(7), crc16(all.first(7))), crc16(all));
}

TEST(Protocol2Encode, PingMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  EXPECT_EQ(encoded(encode_ping(1, buf), buf), kPingId1);
  EXPECT_EQ(encoded(encode_ping(kBroadcastId, buf), buf), kPingBroadcast);
}

TEST(Protocol2Encode, PingStatusMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  const std::uint8_t data1[] = {0x06, 0x04, 0x26};  // model 1030, firmware 38
  EXPECT_EQ(encoded(encode_status(1, 0, data1, buf), buf), kPingStatusId1);
  EXPECT_EQ(encoded(encode_status(2, 0, data1, buf), buf), kPingStatusId2);
}

TEST(Protocol2Encode, ReadMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  EXPECT_EQ(encoded(encode_read(1, xreg::present_position, 4, buf), buf), kReadId1);
  std::uint8_t position[4];
  put_u32(position, 166);
  EXPECT_EQ(encoded(encode_status(1, 0, position, buf), buf), kReadStatusId1);
}

TEST(Protocol2Encode, WriteMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  std::uint8_t goal[4];
  put_u32(goal, 512);
  EXPECT_EQ(encoded(encode_write(1, xreg::goal_position, goal, buf), buf), kWriteId1);
  EXPECT_EQ(encoded(encode_status(1, 0, {}, buf), buf), kEmptyStatusId1);
}

TEST(Protocol2Encode, SyncReadMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  const std::uint8_t ids[] = {1, 2};
  EXPECT_EQ(encoded(encode_sync_read(xreg::present_position, 4, ids, buf), buf), kSyncReadIds12);
  std::uint8_t position[4];
  put_u32(position, 2079);
  EXPECT_EQ(encoded(encode_status(2, 0, position, buf), buf), kSyncReadStatusId2);
}

TEST(Protocol2Encode, SyncWriteMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  const std::uint8_t ids[] = {1, 2};
  std::uint8_t data[8];
  put_u32(data, 150);
  put_u32(data + 4, 170);
  EXPECT_EQ(encoded(encode_sync_write(xreg::goal_position, 4, ids, data, buf), buf),
            kSyncWriteIds12);
}

TEST(Protocol2Encode, SyncWriteRejectsDataOfWrongSize) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  const std::uint8_t ids[] = {1, 2};
  const std::uint8_t data[7] = {};
  EXPECT_EQ(encode_sync_write(xreg::goal_position, 4, ids, data, buf), 0u);
}

TEST(Protocol2Encode, RebootThroughGenericEncoderMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  EXPECT_EQ(encoded(encode_packet(1, inst::reboot, {}, buf), buf), kRebootId1);
}

TEST(Protocol2Encode, OtherManualInstructionsThroughGenericEncoder) {
  struct Example {
    const char* name;
    std::uint8_t id;
    std::uint8_t instruction;
    Bytes params;
    Bytes expected;
  };
  const Example examples[] = {
      // Manual, Reg Write, Example: 200 to Goal Velocity (104) of ID 1.
      {"reg write",
       1,
       inst::reg_write,
       {0x68, 0x00, 0xC8, 0x00, 0x00, 0x00},
       {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x09, 0x00, 0x04, 0x68, 0x00, 0xC8, 0x00, 0x00, 0x00, 0xAE,
        0x8E}},
      // Manual, Action, Example.
      {"action", 1, inst::action, {}, {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x05, 0x02, 0xCE}},
      // Manual, Factory Reset, Example: option 0x01 (all but ID).
      {"factory reset",
       1,
       inst::factory_reset,
       {0x01},
       {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x04, 0x00, 0x06, 0x01, 0xA1, 0xE6}},
      // Manual, Clear, Example: reset the multi-turn information.
      {"clear",
       1,
       inst::clear,
       {0x01, 0x44, 0x58, 0x4C, 0x22},
       {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x10, 0x01, 0x44, 0x58, 0x4C, 0x22, 0xB1, 0xDC}},
      // Manual, Bulk Read, Example: ID 1 Present Input Voltage, ID 2 Present Temperature.
      {"bulk read",
       kBroadcastId,
       inst::bulk_read,
       {0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92, 0x00, 0x01, 0x00},
       {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90,
        0x00, 0x02, 0x00, 0x02, 0x92, 0x00, 0x01, 0x00, 0x1A, 0x05}},
      // Manual, Bulk Write, Example: ID 1 Max Voltage Limit 160, ID 2 Temperature Limit 80.
      {"bulk write",
       kBroadcastId,
       inst::bulk_write,
       {0x01, 0x20, 0x00, 0x02, 0x00, 0xA0, 0x00, 0x02, 0x1F, 0x00, 0x01, 0x00, 0x50},
       {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x10, 0x00, 0x93, 0x01, 0x20, 0x00, 0x02,
        0x00, 0xA0, 0x00, 0x02, 0x1F, 0x00, 0x01, 0x00, 0x50, 0xB7, 0x68}},
  };
  std::array<std::uint8_t, kMaxPacket> buf{};
  for (const Example& e : examples) {
    EXPECT_EQ(encoded(encode_packet(e.id, e.instruction, e.params, buf), buf), e.expected)
        << e.name;
    const auto d = decode_all(e.expected);
    ASSERT_EQ(d.packets.size(), 1u) << e.name;
    EXPECT_EQ(d.params[0], e.params) << e.name;
  }
}

TEST(Protocol2Encode, ReturnsZeroWhenOutputTooSmall) {
  std::array<std::uint8_t, 9> small{};
  EXPECT_EQ(encode_ping(1, small), 0u);
  std::array<std::uint8_t, 10> exact{};
  EXPECT_EQ(encode_ping(1, exact), 10u);
  // Larger than kMaxPacket is refused even with room in `out`.
  std::vector<std::uint8_t> big_out(4 * kMaxPacket);
  const std::vector<std::uint8_t> data(kMaxPacket, 0x11);
  EXPECT_EQ(encode_write(1, 0, data, big_out), 0u);
}

TEST(Protocol2Encode, StuffsHeaderPatternInParams) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  const std::uint8_t data[] = {0xFF, 0xFF, 0xFD, 0x00};
  EXPECT_EQ(encoded(encode_write(1, xreg::goal_position, data, buf), buf), kStuffedWriteId1);
}

TEST(Protocol2Encode, StatusErrorByteCarriesAlertAndNumber) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  const auto error = static_cast<std::uint8_t>(kAlertBit | static_cast<int>(StatusError::access));
  EXPECT_EQ(encoded(encode_status(1, error, {}, buf), buf), kAlertAccessStatusId1);
}

TEST(Protocol2Decode, ManualInstructionPackets) {
  auto d = decode_all(kSyncWriteIds12);
  ASSERT_EQ(d.packets.size(), 1u);
  EXPECT_EQ(d.packets[0].id, kBroadcastId);
  EXPECT_EQ(d.packets[0].instruction, inst::sync_write);
  const Bytes params = {0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00,
                        0x00, 0x00, 0x02, 0xAA, 0x00, 0x00, 0x00};
  EXPECT_EQ(d.params[0], params);

  d = decode_all(kPingId1);
  ASSERT_EQ(d.packets.size(), 1u);
  EXPECT_EQ(d.packets[0].id, 1);
  EXPECT_EQ(d.packets[0].instruction, inst::ping);
  EXPECT_TRUE(d.params[0].empty());
}

TEST(Protocol2Decode, ManualStatusPackets) {
  auto d = decode_all(kPingStatusId1);
  ASSERT_EQ(d.packets.size(), 1u);
  EXPECT_EQ(d.packets[0].instruction, inst::status);
  ASSERT_EQ(d.params[0].size(), 4u);
  EXPECT_EQ(d.params[0][0], 0);                      // error
  EXPECT_EQ(get_u16(d.params[0].data() + 1), 1030);  // model number
  EXPECT_EQ(d.params[0][3], 38);                     // firmware

  d = decode_all(kSyncReadStatusId2);
  ASSERT_EQ(d.packets.size(), 1u);
  EXPECT_EQ(d.packets[0].id, 2);
  EXPECT_EQ(get_u32(d.params[0].data() + 1), 2079u);

  d = decode_all(kBulkReadStatusId2);
  ASSERT_EQ(d.packets.size(), 1u);
  ASSERT_EQ(d.params[0].size(), 2u);
  EXPECT_EQ(d.params[0][1], 36);
}

TEST(Protocol2Decode, StatusErrorBits) {
  auto d = decode_all(kAlertAccessStatusId1);
  ASSERT_EQ(d.packets.size(), 1u);
  const std::uint8_t error = d.params[0][0];
  EXPECT_TRUE(error & kAlertBit);
  EXPECT_EQ(static_cast<StatusError>(error & 0x7F), StatusError::access);

  // Every error number survives a round trip, with and without the alert bit.
  std::array<std::uint8_t, kMaxPacket> buf{};
  for (int number = 0; number <= 7; ++number) {
    for (std::uint8_t alert : {std::uint8_t{0}, kAlertBit}) {
      const auto byte = static_cast<std::uint8_t>(alert | number);
      const std::uint8_t data[] = {0x12};
      d = decode_all(encoded(encode_status(5, byte, data, buf), buf));
      ASSERT_EQ(d.packets.size(), 1u);
      EXPECT_EQ(d.params[0][0], byte);
      EXPECT_EQ(d.params[0][1], 0x12);
    }
  }
}

TEST(Protocol2Decode, CorruptedCrcIsDropped) {
  for (std::size_t i = 4; i < kReadStatusId1.size(); ++i) {
    Bytes bad = kReadStatusId1;
    bad[i] ^= 0x01;
    Decoder d;
    d.feed(bad);
    auto r = drain(d);
    EXPECT_TRUE(r.packets.empty()) << "byte " << i;
    if (i == 5 || i == 6) continue;  // a corrupted LEN may be malformed or need more bytes
    ASSERT_EQ(r.results.size(), 1u) << "byte " << i;
    EXPECT_EQ(r.results[0], DecodeResult::bad_crc) << "byte " << i;
  }
}

TEST(Protocol2Decode, GoodPacketAfterCorruptedOneIsFound) {
  Bytes bytes = kReadStatusId1;
  bytes[9] ^= 0x40;  // data byte
  bytes.insert(bytes.end(), kPingStatusId2.begin(), kPingStatusId2.end());
  const auto d = decode_all(bytes);
  ASSERT_EQ(d.results.size(), 2u);
  EXPECT_EQ(d.results[0], DecodeResult::bad_crc);
  EXPECT_EQ(d.results[1], DecodeResult::packet);
  EXPECT_EQ(d.packets[0].id, 2);
}

TEST(Protocol2Decode, TruncatedPacketNeedsMore) {
  Decoder d;
  d.feed({kReadStatusId1.data(), kReadStatusId1.size() - 1});
  Packet p;
  EXPECT_EQ(d.next(p), DecodeResult::need_more);
  EXPECT_EQ(d.buffered(), kReadStatusId1.size() - 1);
  // After a timeout the caller resets, and the next packet decodes cleanly.
  d.reset();
  d.feed(kPingStatusId1);
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.id, 1);
  EXPECT_EQ(d.stray_bytes(), 0u);
}

TEST(Protocol2Decode, TruncatedPacketFollowedByAnotherIsResynchronised) {
  // The first answer lost its tail; its LEN swallows the start of the next
  // packet, the CRC fails, and the search resumes inside.
  Bytes bytes(kReadStatusId1.begin(), kReadStatusId1.begin() + 10);
  bytes.insert(bytes.end(), kPingStatusId2.begin(), kPingStatusId2.end());
  const auto d = decode_all(bytes);
  ASSERT_EQ(d.packets.size(), 1u);
  EXPECT_EQ(d.packets[0].id, 2);
  EXPECT_EQ(d.results.front(), DecodeResult::bad_crc);
}

TEST(Protocol2Decode, ImpossibleLengthIsMalformed) {
  for (int length : {0, 1, 2, 0xFFFF, static_cast<int>(kMaxPacket)}) {
    Bytes bad = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0, 0, 0x55, 0x00};
    put_u16(bad.data() + 5, static_cast<std::uint16_t>(length));
    bad.insert(bad.end(), kPingStatusId1.begin(), kPingStatusId1.end());
    const auto d = decode_all(bad);
    ASSERT_GE(d.results.size(), 2u) << length;
    EXPECT_EQ(d.results.front(), DecodeResult::malformed) << length;
    ASSERT_EQ(d.packets.size(), 1u) << length;
    EXPECT_EQ(d.params.back(), Bytes({0x00, 0x06, 0x04, 0x26}));
  }
}

TEST(Protocol2Decode, ReservedIdIsMalformed) {
  Bytes bad = kPingId1;
  bad[4] = 0xFD;
  EXPECT_EQ(decode_all(bad).results, std::vector<DecodeResult>{DecodeResult::malformed});
}

TEST(Protocol2Decode, StatusWithoutErrorByteIsMalformed) {
  // Computed: a well-formed frame (valid CRC) whose status has no error byte.
  std::array<std::uint8_t, kMaxPacket> buf{};
  const Bytes p = encoded(encode_packet(1, inst::status, {}, buf), buf);
  EXPECT_EQ(decode_all(p).results, std::vector<DecodeResult>{DecodeResult::malformed});
}

TEST(Protocol2Decode, UnstuffedHeaderInsidePacketIsMalformed) {
  // Computed: params FF FF FD 00 sent without stuffing, with a valid CRC.
  Bytes p = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0xFF, 0xFF, 0xFD, 0x00};
  const std::uint16_t crc = crc16(p);
  p.push_back(static_cast<std::uint8_t>(crc));
  p.push_back(static_cast<std::uint8_t>(crc >> 8));
  EXPECT_EQ(decode_all(p).results.front(), DecodeResult::malformed);
}

TEST(Protocol2Decode, StrayBytesBeforeHeaderAreSkippedAndCounted) {
  Bytes bytes = {0x00, 0x13, 0xFF, 0xFD, 0xFF, 0xFF, 0x55};  // incl. broken header starts
  bytes.insert(bytes.end(), kPingStatusId1.begin(), kPingStatusId1.end());
  Decoder d;
  d.feed(bytes);
  const auto r = drain(d);
  ASSERT_EQ(r.packets.size(), 1u);
  EXPECT_EQ(r.packets[0].id, 1);
  EXPECT_EQ(d.stray_bytes(), 7u);
  EXPECT_EQ(d.buffered(), 0u);
}

TEST(Protocol2Decode, PartialHeaderAtEndIsKept) {
  Decoder d;
  const Bytes junk = {0x01, 0x02, 0xFF, 0xFF, 0xFD};
  d.feed(junk);
  Packet p;
  EXPECT_EQ(d.next(p), DecodeResult::need_more);
  EXPECT_EQ(d.stray_bytes(), 2u);
  EXPECT_EQ(d.buffered(), 3u);
  d.feed({kPingStatusId1.data() + 3, kPingStatusId1.size() - 3});
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.id, 1);
}

TEST(Protocol2Decode, PacketSplitAcrossManyFeeds) {
  Decoder d;
  Packet p;
  // One byte at a time, then in uneven chunks.
  for (std::size_t i = 0; i + 1 < kSyncWriteIds12.size(); ++i) {
    d.feed({&kSyncWriteIds12[i], 1});
    EXPECT_EQ(d.next(p), DecodeResult::need_more) << i;
  }
  d.feed({&kSyncWriteIds12.back(), 1});
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(p.instruction, inst::sync_write);
  EXPECT_EQ(p.params.size(), 14u);

  const std::size_t cuts[] = {3, 8, 14};
  std::size_t from = 0;
  for (std::size_t cut : cuts) {
    d.feed({kReadStatusId1.data() + from, cut - from});
    EXPECT_EQ(d.next(p), DecodeResult::need_more);
    from = cut;
  }
  d.feed({kReadStatusId1.data() + from, kReadStatusId1.size() - from});
  ASSERT_EQ(d.next(p), DecodeResult::packet);
  EXPECT_EQ(get_u32(p.params.data() + 1), 166u);
}

TEST(Protocol2Decode, TwoPacketsInOneFeed) {
  Bytes bytes = kReadStatusId1;
  bytes.insert(bytes.end(), kSyncReadStatusId2.begin(), kSyncReadStatusId2.end());
  const auto d = decode_all(bytes);
  ASSERT_EQ(d.packets.size(), 2u);
  EXPECT_EQ(d.packets[0].id, 1);
  EXPECT_EQ(get_u32(d.params[0].data() + 1), 166u);
  EXPECT_EQ(d.packets[1].id, 2);
  EXPECT_EQ(get_u32(d.params[1].data() + 1), 2079u);
}

TEST(Protocol2Decode, StuffedPacketUnstuffs) {
  const auto d = decode_all(kStuffedWriteId1);
  ASSERT_EQ(d.packets.size(), 1u);
  EXPECT_EQ(d.params[0], Bytes({0x74, 0x00, 0xFF, 0xFF, 0xFD, 0x00}));
}

TEST(Protocol2Decode, StuffingRoundTrip) {
  // Payloads with the header pattern in every position and repeated.
  const std::vector<Bytes> payloads = {
      {0xFF, 0xFF, 0xFD},
      {0xFF, 0xFF, 0xFD, 0xFD},
      {0xFF, 0xFF, 0xFF, 0xFD},
      {0xFF, 0xFF, 0xFD, 0xFF, 0xFF, 0xFD, 0x00},
      {0x01, 0xFF, 0xFF, 0xFD, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0xFF},
      {0xFD, 0xFF, 0xFD, 0xFF, 0xFF},
  };
  std::array<std::uint8_t, kMaxPacket> buf{};
  for (const Bytes& payload : payloads) {
    for (std::uint8_t instruction : {inst::write, inst::status}) {
      const std::size_t n = encode_packet(3, instruction, payload, buf);
      ASSERT_GT(n, 0u);
      EXPECT_EQ(get_u16(buf.data() + 5), n - 7);  // LEN counts the stuffed bytes
      const auto d = decode_all(encoded(n, buf));
      ASSERT_EQ(d.packets.size(), 1u);
      EXPECT_EQ(d.packets[0].instruction, instruction);
      EXPECT_EQ(d.params[0], payload);
    }
  }
}

TEST(Protocol2Decode, LargestPacketFitsAndBufferDrains) {
  // A maximal packet, then more than the buffer holds: feed() reports what
  // fitted and the rest goes in after next().
  std::array<std::uint8_t, kMaxPacket> buf{};
  const std::vector<std::uint8_t> data(kMaxPacket - 7 - 3 - 2, 0x5A);
  const std::size_t n = encode_write(9, 0, data, buf);
  ASSERT_EQ(n, kMaxPacket);
  Bytes stream;
  for (int i = 0; i < 3; ++i) stream.insert(stream.end(), buf.begin(), buf.begin() + n);

  Decoder d;
  std::size_t fed = 0;
  int packets = 0;
  Packet p;
  while (fed < stream.size()) {
    fed += d.feed({stream.data() + fed, stream.size() - fed});
    DecodeResult r;
    while ((r = d.next(p)) != DecodeResult::need_more) {
      ASSERT_EQ(r, DecodeResult::packet);
      EXPECT_EQ(p.params.size(), data.size() + 2);
      ++packets;
    }
  }
  EXPECT_EQ(packets, 3);
  EXPECT_EQ(d.stray_bytes(), 0u);
}

}  // namespace
}  // namespace animrt::dxl
