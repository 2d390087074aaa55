// CANopen frames against examples printed in device manuals that implement
// CiA 301 (the CiA documents themselves are not public):
// - EAO 09 series manual, boot-up sequence "source: CiA CAN poster": node
//   0x0B boot-up 70B [00], heartbeat pre-operational 70B [7F], NMT start
//   000 [01 0B], heartbeat operational 70B [05].
// - Blink Marine PowerTrack CANopen manual: NMT stop node 0x15: 000 [02 15];
//   boot-up 715 [00].
// - ICP DAS CAN-8123 manual: SDO download response from node 1 for 1800h:02:
//   581 [60 00 18 02 00 00 00 00].
// - Curtis 3401T manual: expedited control bytes (write 2F/2B/27/23 for
//   1/2/3/4 bytes, confirm 60, read 40, answer 4F/4B/47/43, abort 80).
// - Faulhaber MC 5010 communications manual: EMCY for following error
//   0x8611, error register 0x20, vendor register 0x0002:
//   [11 86 20 02 00 00 00 00].
// - Vacon OPTC6 manual: SDO read 601 [40 ...], write 601 [2B ...], answers
//   581 [43 ...] / [60 ...].
// PDO payloads (RPDO1 controlword + target, TPDO1 statusword + actual) are
// computed from the CiA 301 little-endian packing rule.

#include "animrt/bridge/can/canopen.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace animrt::canopen {
namespace {

std::vector<int> bytes(const can_frame& f) { return std::vector<int>(f.data, f.data + f.len); }

TEST(CanOpen, NmtAndHeartbeatGoldenFrames) {
  EXPECT_EQ(heartbeat(0x0B, NmtState::boot_up).can_id, 0x70Bu);
  EXPECT_EQ(bytes(heartbeat(0x0B, NmtState::boot_up)), std::vector<int>{0x00});
  EXPECT_EQ(bytes(heartbeat(0x0B, NmtState::pre_operational)), std::vector<int>{0x7F});
  EXPECT_EQ(nmt(NmtCommand::start, 0x0B).can_id, 0x000u);
  EXPECT_EQ(bytes(nmt(NmtCommand::start, 0x0B)), (std::vector<int>{0x01, 0x0B}));
  EXPECT_EQ(bytes(heartbeat(0x0B, NmtState::operational)), std::vector<int>{0x05});
  EXPECT_EQ(bytes(nmt(NmtCommand::stop, 0x15)), (std::vector<int>{0x02, 0x15}));
  EXPECT_EQ(heartbeat(0x15, NmtState::boot_up).can_id, 0x715u);
  EXPECT_EQ(bytes(nmt(NmtCommand::enter_pre_operational, 0)), (std::vector<int>{0x80, 0x00}));
  EXPECT_EQ(bytes(nmt(NmtCommand::reset_node, 3)), (std::vector<int>{0x81, 0x03}));
  EXPECT_EQ(bytes(nmt(NmtCommand::reset_communication, 3)), (std::vector<int>{0x82, 0x03}));
  EXPECT_EQ(bytes(heartbeat(1, NmtState::stopped)), std::vector<int>{0x04});
}

TEST(CanOpen, SyncHasNoData) {
  EXPECT_EQ(sync().can_id, 0x080u);
  EXPECT_EQ(sync().len, 0);
}

TEST(CanOpen, SdoGoldenFrames) {
  const can_frame response = sdo_download_response(1, 0x1800, 0x02);
  EXPECT_EQ(response.can_id, 0x581u);
  EXPECT_EQ(bytes(response), (std::vector<int>{0x60, 0x00, 0x18, 0x02, 0, 0, 0, 0}));
  // Control bytes by size.
  EXPECT_EQ(sdo_download(1, 0x6040, 0, 0x06, 1).data[0], 0x2F);
  EXPECT_EQ(sdo_download(1, 0x6040, 0, 0x06, 2).data[0], 0x2B);
  EXPECT_EQ(sdo_download(1, 0x6040, 0, 0x06, 3).data[0], 0x27);
  EXPECT_EQ(sdo_download(1, 0x6040, 0, 0x06, 4).data[0], 0x23);
  EXPECT_EQ(sdo_upload_response(1, 0x6041, 0, 0, 1).data[0], 0x4F);
  EXPECT_EQ(sdo_upload_response(1, 0x6041, 0, 0, 2).data[0], 0x4B);
  EXPECT_EQ(sdo_upload_response(1, 0x6041, 0, 0, 3).data[0], 0x47);
  EXPECT_EQ(sdo_upload_response(1, 0x6041, 0, 0, 4).data[0], 0x43);
  EXPECT_EQ(sdo_upload(1, 0x6041, 0).data[0], 0x40);
  EXPECT_EQ(sdo_abort(1, 0x6041, 0, 0x06020000).data[0], 0x80);
  // A whole write: controlword = 0x000F to node 1.
  const can_frame write = sdo_download(1, 0x6040, 0, 0x000F, 2);
  EXPECT_EQ(write.can_id, 0x601u);
  EXPECT_EQ(bytes(write), (std::vector<int>{0x2B, 0x40, 0x60, 0x00, 0x0F, 0x00, 0, 0}));
  const can_frame abort = sdo_abort(5, 0x2000, 1, 0x06020000);
  EXPECT_EQ(abort.can_id, 0x585u);
  EXPECT_EQ(bytes(abort), (std::vector<int>{0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x02, 0x06}));
}

TEST(CanOpen, SdoParsing) {
  Sdo s = parse_sdo(sdo_download(3, 0x607A, 0, 0xFFFFF000u, 4));
  EXPECT_EQ(s.kind, SdoKind::download_request);
  EXPECT_EQ(s.index, 0x607A);
  EXPECT_EQ(s.value, 0xFFFFF000u);
  EXPECT_EQ(s.size, 4);
  s = parse_sdo(sdo_upload_response(3, 0x1000, 0, 0x00020192, 4));
  EXPECT_EQ(s.kind, SdoKind::upload_response);
  EXPECT_TRUE(s.expedited);
  EXPECT_EQ(s.value, 0x00020192u);
  s = parse_sdo(sdo_upload_response(3, 0x6061, 0, 0x08, 1));
  EXPECT_EQ(s.size, 1);
  EXPECT_EQ(s.value, 8u);
  EXPECT_EQ(parse_sdo(sdo_upload(3, 0x6041, 0)).kind, SdoKind::upload_request);
  EXPECT_EQ(parse_sdo(sdo_download_response(3, 0x6041, 0)).kind, SdoKind::download_response);
  s = parse_sdo(sdo_abort(3, 0x6041, 0, abort_code::read_only));
  EXPECT_EQ(s.kind, SdoKind::abort);
  EXPECT_EQ(s.value, 0x06010002u);
  can_frame segmented = sdo_download(3, 0x1008, 0, 0, 4);
  segmented.data[0] = 0x21;  // initiate download, size indicated, not expedited
  s = parse_sdo(segmented);
  EXPECT_EQ(s.kind, SdoKind::download_request);
  EXPECT_FALSE(s.expedited);
}

TEST(CanOpen, AbortCodesDecoded) {
  EXPECT_STREQ(sdo_abort_text(0x06020000), "object does not exist in the object dictionary");
  EXPECT_STREQ(sdo_abort_text(0x06010002), "attempt to write a read only object");
  EXPECT_STREQ(sdo_abort_text(0x06090011), "sub-index does not exist");
  EXPECT_STREQ(sdo_abort_text(0x06040041), "object cannot be mapped to the PDO");
  EXPECT_STREQ(sdo_abort_text(0x08000022),
               "data cannot be transferred or stored because of the present device state");
  EXPECT_STREQ(sdo_abort_text(0x12345678), "unknown abort code");
}

TEST(CanOpen, EmcyGoldenFrame) {
  Emcy e;
  e.code = 0x8611;
  e.error_register = 0x20;
  e.vendor[0] = 0x02;
  const can_frame f = emcy(1, e);
  EXPECT_EQ(f.can_id, 0x081u);
  EXPECT_EQ(bytes(f), (std::vector<int>{0x11, 0x86, 0x20, 0x02, 0x00, 0x00, 0x00, 0x00}));
  Emcy back;
  ASSERT_TRUE(parse_emcy(f, back));
  EXPECT_EQ(back.code, 0x8611);
  EXPECT_EQ(back.error_register, 0x20);
  EXPECT_STREQ(emcy_class(0x8611), "positioning controller");
  EXPECT_STREQ(emcy_class(0x2310), "current");
  EXPECT_STREQ(emcy_class(0x4310), "temperature");
  EXPECT_STREQ(emcy_class(0x0000), "error reset");
  EXPECT_STREQ(emcy_class(0xFF01), "device specific");
}

TEST(CanOpen, PdoPayloadsComputedFromTheSpec) {
  // RPDO1 controlword 0x000F, target -1000 counts: little-endian fields.
  std::uint8_t data[6];
  put_le(data, 0x000F, 2);
  put_le(data + 2, static_cast<std::uint32_t>(-1000), 4);
  EXPECT_EQ(std::vector<int>(data, data + 6),
            (std::vector<int>{0x0F, 0x00, 0x18, 0xFC, 0xFF, 0xFF}));
  EXPECT_EQ(static_cast<std::int32_t>(get_le(data + 2, 4)), -1000);
  EXPECT_EQ(mapping(0x6040, 0, 16), 0x60400010u);
  EXPECT_EQ(mapping(0x607A, 0, 32), 0x607A0020u);
}

}  // namespace
}  // namespace animrt::canopen
