// The scan's safe queries on a scripted line: the broadcast ping as the
// Dynamixel e-manual prints it, its answers (the manual's status packets)
// turned into devices, several servos answering as one id reported as a
// collision, an adapter's echo and garbage survived.

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <functional>
#include <vector>

#include "animrt/bridge/commission/serial_scan.hpp"
#include "animrt/bridge/commission/servo_setup.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"

namespace animrt::commission {
namespace {

using Bytes = std::vector<std::uint8_t>;

// e-manual, Ping, Example 2: the broadcast ping, and the status packets of
// ID 1 and ID 2 (XM430-W210, model 1030, firmware 38).
const Bytes kPingBroadcast = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42};
const Bytes kStatusId1 = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00,
                          0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D};
const Bytes kStatusId2 = {0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x07, 0x00,
                          0x55, 0x00, 0x06, 0x04, 0x26, 0x6F, 0x6D};

// A line whose far end answers each request with what `reply` returns.
class ScriptedLine final : public ByteTransport {
 public:
  std::function<Bytes(const Bytes&)> reply;
  bool echo = false;  // a half-duplex adapter that hears itself
  std::vector<Bytes> sent;

  void set_timeout(std::chrono::microseconds) override {}
  bool write(std::span<const std::uint8_t> bytes) override {
    sent.emplace_back(bytes.begin(), bytes.end());
    if (echo) rx_.insert(rx_.end(), bytes.begin(), bytes.end());
    const Bytes answer = reply ? reply(sent.back()) : Bytes{};
    rx_.insert(rx_.end(), answer.begin(), answer.end());
    return true;
  }
  std::size_t read(std::span<std::uint8_t> buffer, std::chrono::microseconds) override {
    const std::size_t n = std::min(buffer.size(), rx_.size());
    std::copy_n(rx_.begin(), n, buffer.begin());
    rx_.erase(rx_.begin(), rx_.begin() + static_cast<long>(n));
    return n;
  }
  void discard_input() override { rx_.clear(); }
  const char* failure() const override { return nullptr; }
  int failure_errno() const override { return 0; }
  std::uint64_t write_failures() const override { return 0; }
  const std::string& port() const override { return port_; }

 private:
  std::deque<std::uint8_t> rx_;
  std::string port_ = "scripted";
};

// An X-series control table (0..147) as a servo at `id` holds it.
Bytes control_table(std::uint8_t id) {
  Bytes t(148, 0);
  dxl::put_u16(&t[dxl::xreg::model_number], 1030);
  t[dxl::xreg::firmware_version] = 38;
  t[dxl::xreg::id] = id;
  t[dxl::xreg::operating_mode] = 3;
  dxl::put_u32(&t[dxl::xreg::max_position_limit], 3000);
  dxl::put_u32(&t[dxl::xreg::min_position_limit], 1000);
  dxl::put_u32(&t[dxl::xreg::present_position], 2100);
  t[dxl::xreg::present_temperature] = 31;
  dxl::put_u16(&t[144], 121);
  return t;
}

Bytes dxl_status(std::uint8_t id, const Bytes& data) {
  Bytes out(dxl::kMaxPacket);
  out.resize(dxl::encode_status(id, 0, data, out));
  return out;
}

// Servos 1 and 2 as the manual's example; `ping_answer` replaces the
// answers to the broadcast ping.
std::function<Bytes(const Bytes&)> two_servos(Bytes ping_answer) {
  return [ping_answer](const Bytes& request) -> Bytes {
    if (request == kPingBroadcast) return ping_answer;
    const std::uint8_t id = request[4];
    if (request[7] == dxl::inst::read && (id == 1 || id == 2)) {
      return dxl_status(id, control_table(id));
    }
    return {};
  };
}

ScanLimits quick() {
  ScanLimits limits;
  limits.answer_timeout = std::chrono::microseconds(1000);
  limits.first_id = 0;
  limits.last_id = 3;
  return limits;
}

TEST(CommissionScan, DynamixelBroadcastPingFindsTheManualsServos) {
  ScriptedLine line;
  Bytes answers = kStatusId1;
  answers.insert(answers.end(), kStatusId2.begin(), kStatusId2.end());
  line.reply = two_servos(answers);
  ScanResult result;
  scan_dynamixel(line, 57600, quick(), result);
  ASSERT_FALSE(line.sent.empty());
  EXPECT_EQ(line.sent.front(), kPingBroadcast);
  ASSERT_EQ(result.devices.size(), 2u);
  EXPECT_TRUE(result.collisions.empty());
  const FoundDevice& d = result.devices[0];
  EXPECT_EQ(d.id, 1);
  EXPECT_EQ(d.baud, 57600);
  EXPECT_EQ(d.protocol, "dynamixel2");
  EXPECT_EQ(d.model, "XM430-W210 (1030)");
  EXPECT_EQ(d.firmware, "38");
  EXPECT_EQ(d.position, 2100);
  EXPECT_EQ(d.min_limit, 1000);
  EXPECT_EQ(d.max_limit, 3000);
  EXPECT_EQ(d.torque_on, false);
  EXPECT_DOUBLE_EQ(*d.voltage_v, 12.1);
  EXPECT_EQ(result.devices[1].id, 2);
}

TEST(CommissionScan, AnAdaptersEchoIsNoServo) {
  ScriptedLine line;
  line.echo = true;
  line.reply = two_servos(kStatusId1);
  ScanResult result;
  scan_dynamixel(line, 1'000'000, quick(), result);
  ASSERT_EQ(result.devices.size(), 1u);
  EXPECT_EQ(result.devices[0].id, 1);
  EXPECT_EQ(result.devices[0].model, "XM430-W210 (1030)");
}

TEST(CommissionScan, TwoAnswersWithOneIdAreACollision) {
  ScriptedLine line;
  Bytes answers = kStatusId1;
  answers.insert(answers.end(), kStatusId1.begin(), kStatusId1.end());
  answers.insert(answers.end(), kStatusId2.begin(), kStatusId2.end());
  line.reply = two_servos(answers);
  ScanResult result;
  scan_dynamixel(line, 57600, quick(), result);
  ASSERT_EQ(result.collisions.size(), 1u);
  EXPECT_EQ(result.collisions[0].id, 1);
  EXPECT_EQ(result.collisions[0].baud, 57600);
  // The collided id is not listed as one device; the other servo is.
  ASSERT_EQ(result.devices.size(), 1u);
  EXPECT_EQ(result.devices[0].id, 2);
}

TEST(CommissionScan, OverlappingAnswersAreACollisionAtTheirId) {
  // Two servos at id 1 answering at once: their bytes interleave on the
  // wire after the common header, and no packet checks out.
  ScriptedLine line;
  Bytes other = kStatusId1;
  other[8] = 0x80;  // the second servo's alert bit differs
  Bytes answers(kStatusId1.begin(), kStatusId1.begin() + 7);
  for (std::size_t i = 7; i < kStatusId1.size(); ++i) {
    answers.push_back(static_cast<std::uint8_t>(kStatusId1[i] | other[i]));
  }
  line.reply = two_servos(answers);
  ScanResult result;
  scan_dynamixel(line, 57600, quick(), result);
  EXPECT_TRUE(result.devices.empty());
  ASSERT_EQ(result.collisions.size(), 1u);
  EXPECT_EQ(result.collisions[0].id, 1);
  EXPECT_NE(result.collisions[0].how.find("damaged"), std::string::npos);
}

TEST(CommissionScan, GarbageIsNoDevice) {
  ScriptedLine line;
  line.reply = [](const Bytes&) { return Bytes{0x00, 0x13, 0xFF, 0xFF, 0x42, 0x99, 0x10}; };
  ScanResult result;
  scan_dynamixel(line, 57600, quick(), result);
  scan_feetech(line, 1'000'000, quick(), result);
  EXPECT_FALSE(scan_maestro(line, 9600, quick(), result));
  EXPECT_TRUE(result.devices.empty());
}

TEST(CommissionScan, FeetechPingAnsweredTwiceIsACollision) {
  ScriptedLine line;
  line.reply = [](const Bytes& request) -> Bytes {
    // Protocol manual, Ping example: FF FF 01 02 01 FB answered FF FF 01 02 00 FC.
    if (request == Bytes{0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB}) {
      return {0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC, 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC};
    }
    return {};
  };
  ScanResult result;
  scan_feetech(line, 1'000'000, quick(), result);
  EXPECT_TRUE(result.devices.empty());
  ASSERT_EQ(result.collisions.size(), 1u);
  EXPECT_EQ(result.collisions[0].id, 1);
}

TEST(CommissionScan, MaestroAnswersGetErrors) {
  ScriptedLine line;
  line.reply = [](const Bytes& request) -> Bytes {
    if (request == Bytes{0xA1}) return {0x20, 0x00};        // serial timeout error
    if (request == Bytes{0x90, 0x00}) return {0x70, 0x17};  // 6000 quarter-us
    return {};
  };
  ScanResult result;
  EXPECT_TRUE(scan_maestro(line, 9600, quick(), result));
  ASSERT_EQ(result.devices.size(), 1u);
  EXPECT_EQ(result.devices[0].protocol, "maestro");
  EXPECT_EQ(result.devices[0].position, 6000);
  EXPECT_NE(result.devices[0].note.find("0x0020"), std::string::npos);
}

TEST(CommissionSetup, TwoServosAnsweringAsOneIdAreRefused) {
  auto open = [](int) {
    auto line = std::make_unique<ScriptedLine>();
    line->reply = [](const Bytes& request) -> Bytes {
      Bytes twice = kStatusId1;
      twice.insert(twice.end(), kStatusId1.begin(), kStatusId1.end());
      return request[4] == 1 ? twice : Bytes{};
    };
    return std::unique_ptr<ByteTransport>(std::move(line));
  };
  try {
    ServoSetup servo(Family::dynamixel2, open, 1, 57600, std::chrono::microseconds(1000));
    FAIL() << "a collided id was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("one servo at a time"), std::string::npos) << e.what();
  }
}

// A servo storing its new ID stays silent a while (a busy EEPROM, a loaded
// host): the read back asks again rather than report the change as failed.
TEST(CommissionSetup, ANewIdReadBackWaitsForALateServo) {
  std::uint8_t id = 1;
  int silent_reads = 12;  // far more than three asks
  auto open = [&](int) {
    auto line = std::make_unique<ScriptedLine>();
    line->reply = [&](const Bytes& request) -> Bytes {
      if (request[4] != id) return {};
      const std::uint8_t instruction = request[7];
      if (instruction == dxl::inst::ping) return kStatusId1;
      const std::uint16_t address = static_cast<std::uint16_t>(request[8] | request[9] << 8);
      if (instruction == dxl::inst::write && address == dxl::xreg::id) {
        id = request[10];
        return {};  // the status would come from the new id: none
      }
      if (instruction != dxl::inst::read) return {};
      if (id != 1 && silent_reads-- > 0) return {};
      const Bytes table = control_table(id);
      const std::uint16_t length = static_cast<std::uint16_t>(request[10] | request[11] << 8);
      return dxl_status(id, Bytes(table.begin() + address, table.begin() + address + length));
    };
    return std::unique_ptr<ByteTransport>(std::move(line));
  };
  ServoSetup servo(Family::dynamixel2, open, 1, 57600, std::chrono::microseconds(1000));
  const std::string said = servo.set_id(5);
  EXPECT_NE(said.find("id 1 -> 5 (read back)"), std::string::npos) << said;
  EXPECT_LT(silent_reads, 0);
}

}  // namespace
}  // namespace animrt::commission
