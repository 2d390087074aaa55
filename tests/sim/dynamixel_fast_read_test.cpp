// The simulated servos' firmware answering Fast Sync Read and Fast Bulk Read
// (against the e-manual's example packets), and the X430 control table:
// access rules and indirect addresses.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/sim/dynamixel_firmware.hpp"

namespace animrt {
namespace {

namespace xreg = dxl::xreg;
using dxl::StatusError;
using Bytes = std::vector<std::uint8_t>;
using sim::Answers;

constexpr Nanos kLater = 100'000'000'000;  // 100 s: every motor has settled

BusConfig servos(std::initializer_list<int> ids, int firmware, const char* model = "XM430-W350") {
  BusConfig config;
  config.name = "legs";
  config.protocol = "dynamixel2";
  config.sim.firmware_version = firmware;
  for (int id : ids) {
    ActuatorBinding b;
    b.joint = "j" + std::to_string(id);
    b.device_id = id;
    dxl::DeviceOptions o;
    o.model_number = dxl::find_x_model(model)->number;
    b.options = o;
    config.actuators.push_back(b);
  }
  return config;
}

// Feeds encoded packets to the firmware as the sim bus would (decoded).
struct FirmwareRig {
  explicit FirmwareRig(const BusConfig& config) : firmware(config, 0) {}

  Answers send(const Bytes& packet, Nanos now) {
    dxl::Decoder d;
    d.feed(packet);
    dxl::Packet p;
    EXPECT_EQ(d.next(p), dxl::DecodeResult::packet);
    Answers out;
    firmware.handle(p, now, out);
    return out;
  }
  Answers send(std::size_t n, Nanos now) { return send(Bytes(buf.begin(), buf.begin() + n), now); }
  std::uint8_t write(std::uint8_t id, std::uint16_t address, const Bytes& data, Nanos now = 0) {
    const Answers a = send(dxl::encode_write(id, address, data, buf), now);
    EXPECT_EQ(a.list.size(), 1u);
    return a.list.empty() ? 0xFF : a.bytes[8];  // the error byte
  }
  void hold_at(std::uint8_t id, std::uint32_t ticks) {
    ASSERT_EQ(write(id, xreg::torque_enable, {1}), 0);
    std::uint8_t v[4];
    dxl::put_u32(v, ticks);
    ASSERT_EQ(write(id, xreg::goal_position, Bytes(v, v + 4)), 0);
  }

  sim::DynamixelFirmware firmware;
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
};

// e-manual Protocol 2.0, Fast Sync Read example: Present Position of IDs
// 3, 7, 4 = 166, 2079, 1023; the manual's devices are XC330-T288, the bytes
// do not depend on the model.
const Bytes kFastSyncRead = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x8A, 0x84,
                             0x00, 0x04, 0x00, 0x03, 0x07, 0x04, 0x20, 0xF2};
const Bytes kFastSyncStatus = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x19, 0x00, 0x55, 0x00, 0x03, 0xA6,
                               0x00, 0x00, 0x00, 0x84, 0x08, 0x00, 0x07, 0x1F, 0x08, 0x00, 0x00,
                               0x16, 0xCA, 0x00, 0x04, 0xFF, 0x03, 0x00, 0x00, 0xD1, 0x9E};
// Fast Bulk Read example: ID 3 Present Position, ID 7 Present PWM (2 bytes
// at 124), ID 4 Present Temperature (1 byte at 146); CRC DA 2D (the manual's
// 20 F2 is a slip, see tests/bridge/protocol2_fast_read_test.cpp).
const Bytes kFastBulkRead = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x12, 0x00, 0x9A, 0x03,
                             0x84, 0x00, 0x04, 0x00, 0x07, 0x7C, 0x00, 0x02, 0x00,
                             0x04, 0x92, 0x00, 0x01, 0x00, 0xDA, 0x2D};

FirmwareRig manual_rig(int firmware = 46) { return FirmwareRig(servos({3, 7, 4}, firmware)); }

TEST(DynamixelSimFastRead, AnswersTheManualFastSyncReadByteForByte) {
  FirmwareRig rig = manual_rig();
  rig.hold_at(3, 166);
  rig.hold_at(7, 2079);
  rig.hold_at(4, 1023);
  const Answers a = rig.send(kFastSyncRead, kLater);
  EXPECT_EQ(a.bytes, kFastSyncStatus);
  // Each servo's part goes out as its own answer (header with the first).
  ASSERT_EQ(a.list.size(), 3u);
  EXPECT_EQ(a.list[0].size, 16u);
  EXPECT_EQ(a.list[1].offset, 16u);
  EXPECT_EQ(a.list[2].size, 8u);
}

TEST(DynamixelSimFastRead, AnswersTheManualFastBulkReadInTheManualsLayout) {
  FirmwareRig rig = manual_rig();
  rig.hold_at(3, 166);
  const Answers a = rig.send(kFastBulkRead, kLater);
  // The manual's ID 7 PWM (421) and ID 4 temperature (31) are not what the
  // simulated motors report (PWM 0, 36 degC); the layout and CRCs are.
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  dxl::FastStatusWriter w(buf, 3, 7);
  w.header();
  const std::uint8_t d3[] = {0xA6, 0, 0, 0}, d7[] = {0, 0}, d4[] = {36};
  w.slice(0, 3, d3);
  w.slice(0, 7, d7);
  w.slice(0, 4, d4);
  EXPECT_EQ(a.bytes, Bytes(buf.begin(), buf.begin() + w.size()));
  ASSERT_EQ(a.bytes.size(), 27u);
  EXPECT_EQ(Bytes(a.bytes.begin(), a.bytes.begin() + 16),
            Bytes({0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x14, 0x00, 0x55, 0x00, 0x03, 0xA6, 0x00, 0x00,
                   0x00, 0x67, 0xA4}));  // the manual's header and ID 3 slice
}

TEST(DynamixelSimFastRead, SilentServoInTheMiddleLeavesItsSliceOut) {
  FirmwareRig rig = manual_rig();
  rig.hold_at(3, 166);
  rig.hold_at(4, 1023);
  rig.firmware.find_configured(7)->set_responding(false);
  const Answers a = rig.send(kFastSyncRead, kLater);
  // Header (LEN still counts three slices) and ID 3's slice as in the
  // manual; then ID 4, its CRC over what was sent before it.
  ASSERT_EQ(a.bytes.size(), kFastSyncStatus.size() - 8);
  EXPECT_EQ(Bytes(a.bytes.begin(), a.bytes.begin() + 16),
            Bytes(kFastSyncStatus.begin(), kFastSyncStatus.begin() + 16));
  dxl::FastStatusReader r(a.bytes);
  EXPECT_FALSE(r.complete());
  dxl::FastSlice s;
  ASSERT_EQ(r.next(4, s), dxl::FastStatusReader::Step::slice);
  ASSERT_EQ(r.next(4, s), dxl::FastStatusReader::Step::slice);
  EXPECT_EQ(s.id, 4);
  EXPECT_EQ(dxl::get_u32(s.data.data()), 1023u);
}

TEST(DynamixelSimFastRead, SilentFirstServoLetsTheNextSendTheHeader) {
  FirmwareRig rig = manual_rig();
  rig.firmware.find_configured(3)->set_responding(false);
  const Answers a = rig.send(kFastSyncRead, kLater);
  dxl::FastStatusReader r(a.bytes);
  ASSERT_TRUE(r.has_header());
  EXPECT_EQ(r.announced_size(), kFastSyncStatus.size());
  dxl::FastSlice s;
  ASSERT_EQ(r.next(4, s), dxl::FastStatusReader::Step::slice);
  EXPECT_EQ(s.id, 7);
}

TEST(DynamixelSimFastRead, ErrorSliceKeepsItsLengthWithZeroData) {
  FirmwareRig rig = manual_rig();
  const std::uint8_t ids[] = {3, 7};
  // 660..663 runs past the table's end (661): Access Error from both.
  const Answers a = rig.send(dxl::encode_fast_sync_read(660, 4, ids, rig.buf), kLater);
  dxl::FastStatusReader r(a.bytes);
  ASSERT_TRUE(r.complete());
  for (std::uint8_t id : ids) {
    dxl::FastSlice s;
    ASSERT_EQ(r.next(4, s), dxl::FastStatusReader::Step::slice);
    EXPECT_EQ(s.id, id);
    EXPECT_EQ(s.error, static_cast<std::uint8_t>(StatusError::access));
    EXPECT_EQ(s.data.size(), 4u);
    EXPECT_EQ(dxl::get_u32(s.data.data()), 0u);
  }
}

TEST(DynamixelSimFastRead, FirmwareBeforeFastReadStaysSilent) {
  FirmwareRig old = manual_rig(44);  // X430 fast read needs firmware 45
  EXPECT_TRUE(old.send(kFastSyncRead, kLater).bytes.empty());
  FirmwareRig dual(servos({3, 7, 4}, 46, "2XL430-W250"));  // never on 2XL/2XC
  EXPECT_TRUE(dual.send(kFastSyncRead, kLater).bytes.empty());
}

TEST(DynamixelSimFastRead, ReportsTheConfiguredModelAndFirmware) {
  FirmwareRig rig(servos({1}, 46, "XH540-W270"));
  std::array<std::uint8_t, 3> info{};
  ASSERT_EQ(rig.firmware.find_configured(1)->read(xreg::model_number, 2, info), StatusError::none);
  EXPECT_EQ(dxl::get_u16(info.data()), 1100);
  EXPECT_EQ(rig.firmware.find_configured(1)->firmware_version(), 46);
  EXPECT_TRUE(rig.firmware.find_configured(1)->fast_read());
}

// ---- control table --------------------------------------------------------

struct Table : ::testing::Test {
  Table() : rig(servos({1}, 46)), servo(*rig.firmware.find_configured(1)) {}
  StatusError write(std::uint16_t address, const Bytes& data) { return servo.write(address, data); }
  StatusError write_u16(std::uint16_t address, std::uint16_t v) {
    std::uint8_t b[2];
    dxl::put_u16(b, v);
    return write(address, Bytes(b, b + 2));
  }
  std::uint32_t read(std::uint16_t address, std::uint16_t length) {
    std::array<std::uint8_t, 4> out{};
    EXPECT_EQ(servo.read(address, length, out), StatusError::none) << address;
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < length; ++i) v |= std::uint32_t{out[i]} << (8 * i);
    return v;
  }
  FirmwareRig rig;
  sim::DynamixelServo& servo;
};

TEST_F(Table, ReadsAsFarAsIndirectData56AndNoFurther) {
  EXPECT_EQ(read(200, 2), 240u);  // Indirect Address 17 starts at Indirect Data 17
  EXPECT_EQ(read(632, 2), 661u);  // Indirect Address 56
  EXPECT_EQ(read(sim::xreg_sim::position_p_gain, 2), 800u);  // the manual's initial value
  std::array<std::uint8_t, 4> out{};
  EXPECT_EQ(servo.read(661, 1, out), StatusError::none);
  EXPECT_EQ(servo.read(661, 2, out), StatusError::access);
  EXPECT_EQ(servo.read(662, 1, out), StatusError::access);
}

TEST_F(Table, EepromIsLockedWhileTorqueIsOn) {
  EXPECT_EQ(write(xreg::return_delay_time, {10}), StatusError::none);
  EXPECT_EQ(write(xreg::torque_enable, {1}), StatusError::none);
  EXPECT_EQ(write(xreg::return_delay_time, {20}), StatusError::access);
  EXPECT_EQ(write_u16(sim::xreg_sim::max_voltage_limit, 150), StatusError::access);
  EXPECT_EQ(read(xreg::return_delay_time, 1), 10u);
  EXPECT_EQ(write(xreg::led, {1}), StatusError::none);  // RAM stays writable
  EXPECT_EQ(write(xreg::torque_enable, {0}), StatusError::none);
  EXPECT_EQ(write_u16(sim::xreg_sim::max_voltage_limit, 150), StatusError::none);
  EXPECT_EQ(read(sim::xreg_sim::max_voltage_limit, 2), 150u);
}

TEST_F(Table, ReadOnlyGapsPartsAndRangesAreRefused) {
  EXPECT_EQ(write(xreg::present_position, {0, 0, 0, 0}), StatusError::access);
  EXPECT_EQ(write(xreg::model_number, {1, 2}), StatusError::access);
  EXPECT_EQ(write(sim::xreg_sim::backup_ready, {1}), StatusError::access);
  EXPECT_EQ(write(14, {0}), StatusError::access);   // no item at 14
  EXPECT_EQ(write(300, {0}), StatusError::access);  // between the indirect blocks
  EXPECT_EQ(write(sim::xreg_sim::position_p_gain, {1}), StatusError::data_length);
  EXPECT_EQ(write(sim::xreg_sim::temperature_limit, {101}), StatusError::data_range);
  EXPECT_EQ(write_u16(sim::xreg_sim::min_voltage_limit, 94), StatusError::data_range);
  // Signed items: Goal Velocity takes -1023..1023.
  std::uint8_t v[4];
  dxl::put_u32(v, static_cast<std::uint32_t>(-1023));
  EXPECT_EQ(write(sim::xreg_sim::goal_velocity, Bytes(v, v + 4)), StatusError::none);
  dxl::put_u32(v, static_cast<std::uint32_t>(-1024));
  EXPECT_EQ(write(sim::xreg_sim::goal_velocity, Bytes(v, v + 4)), StatusError::data_range);
  EXPECT_EQ(write_u16(sim::xreg_sim::position_p_gain, 1234), StatusError::none);
  EXPECT_EQ(read(sim::xreg_sim::position_p_gain, 2), 1234u);
}

TEST_F(Table, IndirectDataReadsTheAddressedRegisters) {
  // Indirect Address 1..4 -> Present Position (132..135).
  for (std::uint16_t k = 0; k < 4; ++k) {
    ASSERT_EQ(write_u16(static_cast<std::uint16_t>(xreg::indirect_address_1 + 2 * k),
                        static_cast<std::uint16_t>(xreg::present_position + k)),
              StatusError::none);
  }
  EXPECT_EQ(read(xreg::indirect_data_1, 4), read(xreg::present_position, 4));
  // The second block: Indirect Address 29 -> Present Temperature.
  ASSERT_EQ(write_u16(xreg::indirect_address_29, xreg::present_temperature), StatusError::none);
  EXPECT_EQ(read(xreg::indirect_data_29, 1), 36u);
}

TEST_F(Table, IndirectDataWritesGoUnderTheTargetsRules) {
  // Indirect Address 5..8 -> Goal Position (116..119); 9 -> Torque Enable;
  // 10 -> Present Temperature (read-only).
  for (std::uint16_t k = 0; k < 4; ++k) {
    ASSERT_EQ(write_u16(static_cast<std::uint16_t>(xreg::indirect_address_1 + 2 * (4 + k)),
                        static_cast<std::uint16_t>(xreg::goal_position + k)),
              StatusError::none);
  }
  ASSERT_EQ(
      write_u16(static_cast<std::uint16_t>(xreg::indirect_address_1 + 2 * 8), xreg::torque_enable),
      StatusError::none);
  ASSERT_EQ(write_u16(static_cast<std::uint16_t>(xreg::indirect_address_1 + 2 * 9),
                      xreg::present_temperature),
            StatusError::none);
  const std::uint16_t data5 = xreg::indirect_data_1 + 4;
  EXPECT_EQ(write(data5, {0x00, 0x04, 0x00, 0x00}), StatusError::none);  // 1024
  EXPECT_EQ(read(xreg::goal_position, 4), 1024u);
  EXPECT_EQ(read(data5, 4), 1024u);
  EXPECT_EQ(write(data5, {0x00, 0x08}), StatusError::data_length);             // half the item
  EXPECT_EQ(write(data5, {0x00, 0x10, 0x00, 0x00}), StatusError::data_limit);  // 4096 > max
  EXPECT_EQ(read(xreg::goal_position, 4), 1024u);
  // Torque Enable through Indirect Data 9, with its range (0..1).
  const auto data9 = static_cast<std::uint16_t>(xreg::indirect_data_1 + 8);
  EXPECT_EQ(write(data9, {2}), StatusError::data_range);
  EXPECT_EQ(write(data9, {1}), StatusError::none);
  EXPECT_TRUE(servo.torque_on());
  // Goal, torque and a read-only register in one write: all refused.
  EXPECT_EQ(write(data5, {0x00, 0x02, 0x00, 0x00, 0x00, 36}), StatusError::access);
  EXPECT_EQ(read(xreg::goal_position, 4), 1024u);
  EXPECT_TRUE(servo.torque_on());
  // Goal and torque at once: two runs of target addresses, one write.
  EXPECT_EQ(write(data5, {0x00, 0x02, 0x00, 0x00, 0x00}), StatusError::none);
  EXPECT_EQ(read(xreg::goal_position, 4), 512u);
  EXPECT_FALSE(servo.torque_on());
}

TEST_F(Table, IndirectAddressesTakeOnlyAddresses64To661) {
  // Not the EEPROM: the manual gives Indirect Address the range 64..661.
  EXPECT_EQ(write_u16(xreg::indirect_address_1, xreg::id), StatusError::data_range);
  EXPECT_EQ(write_u16(xreg::indirect_address_1, 63), StatusError::data_range);
  EXPECT_EQ(write_u16(xreg::indirect_address_1, 662), StatusError::data_range);
  EXPECT_EQ(write_u16(xreg::indirect_address_1, 64), StatusError::none);
  EXPECT_EQ(write_u16(xreg::indirect_address_29 + 2 * 27, 661), StatusError::none);
  EXPECT_EQ(write(xreg::indirect_address_1 + 1, {0}), StatusError::data_length);  // half
}

TEST_F(Table, RebootRestoresTheIndirectAddresses) {
  ASSERT_EQ(write_u16(xreg::indirect_address_1, xreg::present_position), StatusError::none);
  servo.reboot(0);
  EXPECT_EQ(read(xreg::indirect_address_1, 2), xreg::indirect_data_1);
}

}  // namespace
}  // namespace animrt
