// Fast Sync Read (0x8A) and Fast Bulk Read (0x9A) against the example packets
// of the ROBOTIS e-manual, "DYNAMIXEL Protocol 2.0"
// (https://emanual.robotis.com/docs/en/dxl/protocol2/, source
// docs/en/dxl/protocol2.md in github.com/ROBOTIS-GIT/emanual). The manual
// prints each device's part of the one status packet in its own table; the
// vectors below are those parts back to back, as they appear on the wire.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "bridge/encoded.hpp"

namespace animrt::dxl {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Fast Sync Read example: Present Position (132, 4 bytes) of IDs 3, 7, 4
// (XC330-T288) = 166, 2079, 1023.
const Bytes kFastSyncRead = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x8A, 0x84,
                             0x00, 0x04, 0x00, 0x03, 0x07, 0x04, 0x20, 0xF2};
const Bytes kFastSyncStatus = {
    0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x19, 0x00, 0x55,   // header, sent by ID 3
    0x00, 0x03, 0xA6, 0x00, 0x00, 0x00, 0x84, 0x08,   // ID 3
    0x00, 0x07, 0x1F, 0x08, 0x00, 0x00, 0x16, 0xCA,   // ID 7
    0x00, 0x04, 0xFF, 0x03, 0x00, 0x00, 0xD1, 0x9E};  // ID 4
// Fast Bulk Read example: ID 3 Present Position (132, 4) = 166, ID 7 Present
// PWM (124, 2) = 421, ID 4 Present Temperature (146, 1) = 31. The manual
// prints the instruction's CRC as 20 F2, the Fast Sync Read example's CRC: a
// slip; the CRC of these bytes is DA 2D (computed, and cross-checked with a
// bit-by-bit CRC in Python). Its status packet's CRCs are as printed.
const Bytes kFastBulkRead = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x12, 0x00, 0x9A, 0x03,
                             0x84, 0x00, 0x04, 0x00, 0x07, 0x7C, 0x00, 0x02, 0x00,
                             0x04, 0x92, 0x00, 0x01, 0x00, 0xDA, 0x2D};
const Bytes kFastBulkStatus = {
    0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x14, 0x00, 0x55,  // header, sent by ID 3
    0x00, 0x03, 0xA6, 0x00, 0x00, 0x00, 0x67, 0xA4,  // ID 3
    0x00, 0x07, 0xA5, 0x01, 0x24, 0x74,              // ID 7
    0x00, 0x04, 0x1F, 0xD9, 0xC1};                   // ID 4
// Bulk Read example (plain): ID 1 Present Voltage (144, 2), ID 2 Present
// Temperature (146, 1).
const Bytes kBulkRead = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90,
                         0x00, 0x02, 0x00, 0x02, 0x92, 0x00, 0x01, 0x00, 0x1A, 0x05};

const BulkReadEntry kFastBulkEntries[] = {{3, 132, 4}, {7, 124, 2}, {4, 146, 1}};

Bytes build_fast_status(std::span<const FastSlice> slices, std::size_t asked,
                        std::size_t data_bytes) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  FastStatusWriter w(buf, asked, data_bytes);
  w.header();
  for (const FastSlice& s : slices) EXPECT_TRUE(w.slice(s.error, s.id, s.data));
  return encoded(w.size(), buf);
}

TEST(Protocol2FastRead, FastSyncReadInstructionMatchesManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  const std::uint8_t ids[] = {3, 7, 4};
  EXPECT_EQ(encoded(encode_fast_sync_read(132, 4, ids, buf), buf), kFastSyncRead);
}

TEST(Protocol2FastRead, BulkReadInstructionsMatchManual) {
  std::array<std::uint8_t, kMaxPacket> buf{};
  EXPECT_EQ(encoded(encode_fast_bulk_read(kFastBulkEntries, buf), buf), kFastBulkRead);
  const BulkReadEntry plain[] = {{1, 144, 2}, {2, 146, 1}};
  EXPECT_EQ(encoded(encode_bulk_read(plain, buf), buf), kBulkRead);
}

TEST(Protocol2FastRead, FastSyncStatusMatchesManual) {
  const std::uint8_t d3[] = {0xA6, 0, 0, 0}, d7[] = {0x1F, 0x08, 0, 0}, d4[] = {0xFF, 0x03, 0, 0};
  const FastSlice slices[] = {{0, 3, d3}, {0, 7, d7}, {0, 4, d4}};
  EXPECT_EQ(build_fast_status(slices, 3, 12), kFastSyncStatus);
  EXPECT_EQ(fast_status_size(3, 12), kFastSyncStatus.size());
}

TEST(Protocol2FastRead, FastBulkStatusMatchesManual) {
  const std::uint8_t d3[] = {0xA6, 0, 0, 0}, d7[] = {0xA5, 0x01}, d4[] = {0x1F};
  const FastSlice slices[] = {{0, 3, d3}, {0, 7, d7}, {0, 4, d4}};
  EXPECT_EQ(build_fast_status(slices, 3, 7), kFastBulkStatus);
}

TEST(Protocol2FastRead, WholeStatusPacketCarriesTheLastSlicesCrc) {
  // The last slice's CRC is the CRC of the whole packet, as for any packet.
  const std::size_t n = kFastSyncStatus.size();
  EXPECT_EQ(crc16({kFastSyncStatus.data(), n - 2}), get_u16(kFastSyncStatus.data() + n - 2));
}

TEST(Protocol2FastRead, ReaderTakesTheManualFastSyncStatusApart) {
  Bytes stream = kFastSyncRead;  // a half-duplex adapter's echo comes first
  stream.insert(stream.end(), kFastSyncStatus.begin(), kFastSyncStatus.end());
  FastStatusReader r(stream);
  ASSERT_TRUE(r.has_header());
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.announced_size(), kFastSyncStatus.size());
  const std::uint8_t ids[] = {3, 7, 4};
  const std::uint32_t values[] = {166, 2079, 1023};
  for (int i = 0; i < 3; ++i) {
    std::uint8_t id = 0;
    ASSERT_TRUE(r.peek_id(id));
    EXPECT_EQ(id, ids[i]);
    FastSlice s;
    ASSERT_EQ(r.next(4, s), FastStatusReader::Step::slice);
    EXPECT_EQ(s.error, 0);
    EXPECT_EQ(s.id, ids[i]);
    ASSERT_EQ(s.data.size(), 4u);
    EXPECT_EQ(get_u32(s.data.data()), values[i]);
  }
  FastSlice s;
  EXPECT_EQ(r.next(4, s), FastStatusReader::Step::end);
}

TEST(Protocol2FastRead, ReaderTakesTheManualFastBulkStatusApart) {
  FastStatusReader r(kFastBulkStatus);
  const std::size_t lengths[] = {4, 2, 1};
  const std::uint32_t values[] = {166, 421, 31};
  for (int i = 0; i < 3; ++i) {
    FastSlice s;
    ASSERT_EQ(r.next(lengths[i], s), FastStatusReader::Step::slice) << i;
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < s.data.size(); ++k) v |= std::uint32_t{s.data[k]} << (8 * k);
    EXPECT_EQ(v, values[i]);
  }
}

TEST(Protocol2FastRead, DataThatLooksLikeAHeaderIsNotStuffed) {
  // Position 0x00FDFFFF: the bytes FF FF FD go out as they are, no extra FD.
  const std::uint8_t d[] = {0xFF, 0xFF, 0xFD, 0x00};
  const FastSlice slices[] = {{0, 1, d}};
  const Bytes packet = build_fast_status(slices, 1, 4);
  EXPECT_EQ(packet.size(), fast_status_size(1, 4));
  FastStatusReader r(packet);
  FastSlice s;
  ASSERT_EQ(r.next(4, s), FastStatusReader::Step::slice);
  EXPECT_EQ(get_u32(s.data.data()), 0x00FDFFFFu);
}

TEST(Protocol2FastRead, SilentDeviceInTheMiddleLeavesTheOthersReadable) {
  // ID 7 does not answer: ID 3 sends the header (LEN for all three) and its
  // slice, ID 4 its slice with the CRC of what was on the wire before it.
  const std::uint8_t d3[] = {0xA6, 0, 0, 0}, d4[] = {0xFF, 0x03, 0, 0};
  const FastSlice slices[] = {{0, 3, d3}, {0, 4, d4}};
  const Bytes packet = build_fast_status(slices, 3, 12);
  ASSERT_EQ(packet.size(), kFastSyncStatus.size() - 8);
  EXPECT_EQ(Bytes(packet.begin(), packet.begin() + 16),
            Bytes(kFastSyncStatus.begin(), kFastSyncStatus.begin() + 16));
  FastStatusReader r(packet);
  EXPECT_FALSE(r.complete());  // shorter than LEN announces
  FastSlice s;
  ASSERT_EQ(r.next(4, s), FastStatusReader::Step::slice);
  EXPECT_EQ(s.id, 3);
  ASSERT_EQ(r.next(4, s), FastStatusReader::Step::slice);
  EXPECT_EQ(s.id, 4);
  EXPECT_EQ(get_u32(s.data.data()), 1023u);
  EXPECT_EQ(r.next(4, s), FastStatusReader::Step::end);
}

TEST(Protocol2FastRead, DamagedSliceStopsTheReaderAfterTheGoodOnes) {
  Bytes damaged = kFastSyncStatus;
  damaged[18] ^= 0x01;  // a data byte of ID 7
  FastStatusReader r(damaged);
  FastSlice s;
  ASSERT_EQ(r.next(4, s), FastStatusReader::Step::slice);
  EXPECT_EQ(s.id, 3);
  EXPECT_EQ(r.next(4, s), FastStatusReader::Step::bad_crc);
  EXPECT_EQ(r.next(4, s), FastStatusReader::Step::end);
}

TEST(Protocol2FastRead, CutShortSliceIsReportedShort) {
  const Bytes cut(kFastSyncStatus.begin(), kFastSyncStatus.begin() + 20);
  FastStatusReader r(cut);
  FastSlice s;
  ASSERT_EQ(r.next(4, s), FastStatusReader::Step::slice);
  std::uint8_t id = 0;
  ASSERT_TRUE(r.peek_id(id));
  EXPECT_EQ(id, 7);
  EXPECT_EQ(r.next(4, s), FastStatusReader::Step::short_);
}

TEST(Protocol2FastRead, NoHeaderNoSlices) {
  FastStatusReader r(kFastSyncRead);  // only the instruction's echo
  EXPECT_FALSE(r.has_header());
  EXPECT_FALSE(r.complete());
  FastSlice s;
  EXPECT_EQ(r.next(4, s), FastStatusReader::Step::end);
}

TEST(Protocol2FastRead, WriterRefusesWhatDoesNotFit) {
  std::array<std::uint8_t, 20> small{};
  FastStatusWriter w(small, 2, 8);
  w.header();
  const std::uint8_t d[] = {1, 2, 3, 4};
  EXPECT_TRUE(w.slice(0, 1, d));
  EXPECT_FALSE(w.slice(0, 2, d));
  EXPECT_EQ(w.size(), 16u);
}

}  // namespace
}  // namespace animrt::dxl
