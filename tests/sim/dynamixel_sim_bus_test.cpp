// The simulated X-series bus driven through a real pty with raw termios, as
// any Protocol 2.0 client would: instruction bytes out, status packets in.

#include "animrt/sim/dynamixel_sim_bus.hpp"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "animrt/core/error.hpp"
#include "sim/pty_client.hpp"

namespace animrt {
namespace {

using dxl::StatusError;
using test::Bytes;
using test::PtyClient;
namespace xreg = dxl::xreg;
namespace xreg_sim = sim::xreg_sim;

constexpr std::uint8_t err(StatusError e) { return static_cast<std::uint8_t>(e); }

BusConfig make_config(std::initializer_list<int> ids = {1, 2, 3}) {
  BusConfig config;
  config.name = "legs";
  config.protocol = "dynamixel2";
  config.baud = 1'000'000;
  for (int id : ids) {
    ActuatorBinding b;
    b.joint = "joint" + std::to_string(id);
    b.joint_index = id - 1;
    b.device_id = id;
    config.actuators.push_back(b);
  }
  return config;
}

// Ticks of the documented start offset: (2 + id % 3) degrees, + for odd ids.
std::int32_t start_ticks(int id) {
  const double degrees = (id % 2 == 1 ? 1 : -1) * (2 + id % 3);
  return ActuatorBinding{}.to_ticks(degrees * std::numbers::pi / 180.0);
}

std::int32_t as_i32(const Bytes& data) {
  return static_cast<std::int32_t>(dxl::get_u32(data.data()));
}

class DynamixelSimBusTest : public ::testing::Test {
 protected:
  void SetUp() override { open(make_config()); }

  void open(const BusConfig& config) {
    client_.reset();
    bus_.reset();
    config_ = config;
    bus_ = std::make_unique<sim::DynamixelSimBus>(config_, clock_);
    bus_->start();
    client_ = std::make_unique<PtyClient>(bus_->endpoint());
  }

  test::Status transact(const Bytes& instruction) { return client_->transact(instruction); }

  // Sends `bytes` and returns once the servos' side has read them: on a
  // loaded machine its thread may not run for longer than any silence a
  // test leaves, and would read what was sent apart as one burst.
  void send_and_wait_read(const Bytes& bytes) {
    client_->send(bytes);
    ASSERT_TRUE(test::handled_all(*client_, *bus_));
  }

  std::int32_t read_i32(std::uint8_t id, std::uint16_t address) {
    const auto s = transact(test::read(id, address, 4));
    EXPECT_EQ(s.error, 0);
    EXPECT_EQ(s.data.size(), 4u);
    return s.data.size() == 4 ? as_i32(s.data) : 0;
  }
  std::uint8_t read_u8(std::uint8_t id, std::uint16_t address) {
    const auto s = transact(test::read(id, address, 1));
    EXPECT_EQ(s.data.size(), 1u);
    return s.data.empty() ? 0 : s.data[0];
  }
  std::uint8_t write_u8(std::uint8_t id, std::uint16_t address, std::uint8_t value) {
    return transact(test::write(id, address, {value})).error;
  }
  std::uint8_t write_u32(std::uint8_t id, std::uint16_t address, std::uint32_t value) {
    return transact(test::write_u32(id, address, value)).error;
  }

  ManualClock clock_{0};
  BusConfig config_;
  std::unique_ptr<sim::DynamixelSimBus> bus_;
  std::unique_ptr<PtyClient> client_;
};

TEST_F(DynamixelSimBusTest, EndpointIsAPtyAndDescribeNamesIt) {
  EXPECT_EQ(bus_->endpoint().rfind("/dev/pts/", 0), 0u) << bus_->endpoint();
  EXPECT_EQ(bus_->describe(), "serial legs " + bus_->endpoint());
}

TEST_F(DynamixelSimBusTest, PingOfId1AnswersTheManualStatusPacket) {
  // e-manual Protocol 2.0, Ping Example 1 (instruction and ID 1 status packet).
  client_->send({0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E});
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00,
                          0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D};
  EXPECT_EQ(client_->read_raw(expected.size()), expected);
  EXPECT_TRUE(client_->silent());
}

TEST_F(DynamixelSimBusTest, BroadcastPingAnswersInIdOrderAsInTheManual) {
  open(make_config({2, 1}));  // config order differs from id order
  // e-manual Protocol 2.0, Ping Example 2: broadcast ping, status of ID 1 then ID 2.
  client_->send({0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42});
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06,
                          0x04, 0x26, 0x65, 0x5D, 0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x07,
                          0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x6F, 0x6D};
  EXPECT_EQ(client_->read_raw(expected.size()), expected);
  EXPECT_TRUE(client_->silent());
}

TEST_F(DynamixelSimBusTest, ControlTableIdentityAndDefaults) {
  const auto s = transact(test::read(2, 0, 12));  // model .. operating mode
  ASSERT_EQ(s.error, 0);
  ASSERT_EQ(s.data.size(), 12u);
  EXPECT_EQ(dxl::get_u16(&s.data[xreg::model_number]), 1030);
  EXPECT_EQ(s.data[xreg::firmware_version], 38);
  EXPECT_EQ(s.data[xreg::id], 2);
  EXPECT_EQ(s.data[xreg::baud_rate], 3);  // 1 Mbps
  EXPECT_EQ(s.data[xreg::return_delay_time], 0);
  EXPECT_EQ(s.data[xreg::operating_mode], 3);
  EXPECT_EQ(read_i32(2, xreg::min_position_limit), 0);
  EXPECT_EQ(read_i32(2, xreg::max_position_limit), 4095);
  EXPECT_EQ(read_u8(2, xreg::torque_enable), 0);
  EXPECT_EQ(read_u8(2, xreg::status_return_level), 2);
  EXPECT_EQ(read_u8(2, xreg::hardware_error_status), 0);
  EXPECT_EQ(read_u8(2, xreg::present_temperature), 36);
  // Velocity Limit covers the configured max speed (6 rad/s ~ 57.3 rpm).
  EXPECT_EQ(read_i32(2, xreg::velocity_limit), 251);
}

TEST_F(DynamixelSimBusTest, StartsAtTheDocumentedOffsetFromZero) {
  for (int id : {1, 2, 3}) {
    EXPECT_EQ(read_i32(static_cast<std::uint8_t>(id), xreg::present_position), start_ticks(id));
    EXPECT_EQ(read_i32(static_cast<std::uint8_t>(id), xreg::goal_position), start_ticks(id));
    EXPECT_NEAR(bus_->device_position(id), config_.actuators[0].to_rad(start_ticks(id)), 1e-9);
  }
  EXPECT_NEAR(bus_->device_position(1), 3.0 * std::numbers::pi / 180.0, 1e-3);
  EXPECT_NEAR(bus_->device_position(2), -4.0 * std::numbers::pi / 180.0, 1e-3);
}

TEST_F(DynamixelSimBusTest, ReadWriteRoundTrip) {
  // e-manual Protocol 2.0, Write Example (512 to Goal Position of ID 1) and
  // its status packet.
  client_->send({0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0x00, 0x02, 0x00, 0x00,
                 0xCA, 0x89});
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C};
  EXPECT_EQ(client_->read_raw(expected.size()), expected);
  EXPECT_EQ(read_i32(1, xreg::goal_position), 512);

  EXPECT_EQ(write_u8(3, xreg::led, 1), 0);
  EXPECT_EQ(read_u8(3, xreg::led), 1);
  EXPECT_EQ(read_u8(1, xreg::led), 0);
  // Several items in one write: Torque Enable and LED.
  EXPECT_EQ(transact(test::write(2, xreg::torque_enable, {1, 1})).error, 0);
  const auto s = transact(test::read(2, xreg::torque_enable, 2));
  EXPECT_EQ(s.data, Bytes({1, 1}));
}

TEST_F(DynamixelSimBusTest, SyncWriteThenSyncRead) {
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  const std::uint8_t ids[] = {1, 2, 3};
  std::uint8_t data[12];
  dxl::put_u32(data, 1000);
  dxl::put_u32(data + 4, 2000);
  dxl::put_u32(data + 8, 3000);
  const std::size_t n = dxl::encode_sync_write(xreg::goal_position, 4, ids, data, buf);
  client_->send(Bytes(buf.begin(), buf.begin() + n));
  EXPECT_TRUE(client_->silent());  // Sync Write has no answer

  const std::uint8_t order[] = {3, 1, 2};
  const std::size_t m = dxl::encode_sync_read(xreg::goal_position, 4, order, buf);
  client_->send(Bytes(buf.begin(), buf.begin() + m));
  const auto answers = client_->read_status(3);
  ASSERT_EQ(answers.size(), 3u);
  EXPECT_EQ(answers[0].id, 3);
  EXPECT_EQ(as_i32(answers[0].data), 3000);
  EXPECT_EQ(answers[1].id, 1);
  EXPECT_EQ(as_i32(answers[1].data), 1000);
  EXPECT_EQ(answers[2].id, 2);
  EXPECT_EQ(as_i32(answers[2].data), 2000);
  EXPECT_TRUE(client_->silent());
}

TEST_F(DynamixelSimBusTest, SyncReadOfTheManualExample) {
  // e-manual Protocol 2.0, Sync Read Example: Present Position of IDs 1, 2.
  client_->send({0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x09, 0x00, 0x82, 0x84, 0x00, 0x04, 0x00, 0x01, 0x02,
                 0xCE, 0xFA});
  const auto answers = client_->read_status(2);
  ASSERT_EQ(answers.size(), 2u);
  EXPECT_EQ(answers[0].id, 1);
  EXPECT_EQ(as_i32(answers[0].data), start_ticks(1));
  EXPECT_EQ(answers[1].id, 2);
  EXPECT_EQ(as_i32(answers[1].data), start_ticks(2));
}

TEST_F(DynamixelSimBusTest, BulkReadAnswersInListOrder) {
  // Computed, laid out as the manual's Bulk Read example: ID 1 Present Input
  // Voltage (144, 2 bytes), ID 2 Present Temperature (146, 1 byte).
  client_->send(test::packet(dxl::kBroadcastId, dxl::inst::bulk_read,
                             {0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92, 0x00, 0x01, 0x00}));
  const auto answers = client_->read_status(2);
  ASSERT_EQ(answers.size(), 2u);
  EXPECT_EQ(answers[0].id, 1);
  EXPECT_EQ(dxl::get_u16(answers[0].data.data()), 120);  // 12.0 V
  EXPECT_EQ(answers[1].id, 2);
  EXPECT_EQ(answers[1].data, Bytes({36}));
}

TEST_F(DynamixelSimBusTest, BulkWriteWritesEachDevice) {
  Bytes params = {0x01, 0x41, 0x00, 0x01, 0x00, 0x01};                        // ID 1 LED = 1
  const Bytes goal = {0x02, 0x74, 0x00, 0x04, 0x00, 0xD0, 0x07, 0x00, 0x00};  // ID 2 goal 2000
  params.insert(params.end(), goal.begin(), goal.end());
  client_->send(test::packet(dxl::kBroadcastId, dxl::inst::bulk_write, params));
  EXPECT_TRUE(client_->silent());
  EXPECT_EQ(read_u8(1, xreg::led), 1);
  EXPECT_EQ(read_i32(2, xreg::goal_position), 2000);
}

TEST_F(DynamixelSimBusTest, MotorMovesTowardGoalNoFasterThanMaxSpeedAndSettles) {
  const double vmax_ticks = config_.sim.max_speed_rad_s * config_.actuators[0].ticks_per_rad;
  const std::int32_t start = start_ticks(1);
  const std::int32_t goal = start + 1000;
  ASSERT_EQ(write_u8(1, xreg::torque_enable, 1), 0);
  ASSERT_EQ(write_u32(1, xreg::goal_position, static_cast<std::uint32_t>(goal)), 0);

  const Nanos step = from_seconds(0.01);
  std::int32_t previous = start;
  bool saw_moving = false;
  for (int i = 1; i <= 100; ++i) {
    clock_.advance(step);
    const std::int32_t position = read_i32(1, xreg::present_position);
    EXPECT_LE(position - previous, std::ceil(vmax_ticks * 0.01) + 1) << "step " << i;
    EXPECT_GE(position, previous) << "step " << i;  // toward the goal, never back
    EXPECT_LE(position, goal) << "step " << i;      // no overshoot
    if (i == 10) {
      // Still on the rate limit after 0.1 s: exactly vmax * t travelled.
      EXPECT_NEAR(position, start + vmax_ticks * 0.1, 1.0);
      const std::int32_t velocity = read_i32(1, xreg::present_velocity);
      EXPECT_NEAR(velocity, vmax_ticks / 4096.0 * 60.0 / 0.229, 1.0);  // unit 0.229 rpm
    }
    saw_moving = saw_moving || read_u8(1, xreg::moving) == 1;
    previous = position;
  }
  EXPECT_TRUE(saw_moving);
  EXPECT_EQ(read_i32(1, xreg::present_position), goal);
  EXPECT_EQ(read_i32(1, xreg::present_velocity), 0);
  EXPECT_EQ(read_u8(1, xreg::moving), 0);
  EXPECT_NEAR(bus_->device_position(1), config_.actuators[0].to_rad(goal), 1e-6);
  // Servos that were not commanded did not move.
  EXPECT_EQ(read_i32(2, xreg::present_position), start_ticks(2));
}

TEST_F(DynamixelSimBusTest, LockstepSyncWriteTakesEffectInTheCycleItWasSent) {
  // The serving thread may see a Sync Write only after the loop moved the
  // clock on; force that order and check the goal still counts from the
  // cycle it was sent in.
  const double vmax_ticks = config_.sim.max_speed_rad_s * config_.actuators[0].ticks_per_rad;
  const std::int32_t start = start_ticks(1);
  ASSERT_EQ(write_u8(1, xreg::torque_enable, 1), 0);  // answered at t = 0
  bus_->stop();
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  const std::uint8_t ids[] = {1};
  std::uint8_t goal[4];
  dxl::put_u32(goal, static_cast<std::uint32_t>(start + 1000));
  const std::size_t n = dxl::encode_sync_write(xreg::goal_position, 4, ids, goal, buf);
  client_->send(Bytes(buf.begin(), buf.begin() + n));
  clock_.advance(from_seconds(0.1));
  client_->send(test::read(1, xreg::present_position, 4));
  bus_->start();
  const auto answers = client_->read_status(1);
  ASSERT_EQ(answers.size(), 1u);
  EXPECT_NEAR(as_i32(answers[0].data), start + vmax_ticks * 0.1, 1.0);
}

TEST_F(DynamixelSimBusTest, FirstOrderLagNearTheGoal) {
  // A step smaller than vmax * tau is a pure exponential: e(t) = e0 exp(-t / tau).
  const double tau = config_.sim.time_constant_s;
  const std::int32_t start = start_ticks(1);
  ASSERT_EQ(write_u8(1, xreg::torque_enable, 1), 0);
  ASSERT_EQ(write_u32(1, xreg::goal_position, static_cast<std::uint32_t>(start + 40)), 0);
  clock_.advance(from_seconds(tau));
  EXPECT_NEAR(read_i32(1, xreg::present_position), start + 40 - 40 * std::exp(-1.0), 0.5);
}

TEST_F(DynamixelSimBusTest, TorqueOffMeansNoMotion) {
  const std::int32_t start = start_ticks(1);
  ASSERT_EQ(write_u32(1, xreg::goal_position, static_cast<std::uint32_t>(start + 500)), 0);
  clock_.advance(from_seconds(1.0));
  EXPECT_EQ(read_i32(1, xreg::present_position), start);
  EXPECT_EQ(read_i32(1, xreg::present_velocity), 0);

  // Torque off in the middle of a move stops it where it is.
  ASSERT_EQ(write_u8(1, xreg::torque_enable, 1), 0);
  clock_.advance(from_seconds(0.05));
  ASSERT_EQ(write_u8(1, xreg::torque_enable, 0), 0);
  const std::int32_t stopped = read_i32(1, xreg::present_position);
  EXPECT_GT(stopped, start);
  EXPECT_LT(stopped, start + 500);
  clock_.advance(from_seconds(1.0));
  EXPECT_EQ(read_i32(1, xreg::present_position), stopped);
  EXPECT_EQ(read_i32(1, xreg::present_velocity), 0);
}

TEST_F(DynamixelSimBusTest, BadCrcIsIgnoredAndCounted) {
  Bytes bad = test::ping(1);
  bad.back() ^= 0x5A;
  send_and_wait_read(bad);
  EXPECT_TRUE(client_->silent());
  EXPECT_EQ(bus_->stats().crc_errors, 1u);
  // A corrupted write changes nothing.
  Bytes bad_write = test::write(1, xreg::led, {1});
  bad_write[9] ^= 0x01;
  send_and_wait_read(bad_write);
  EXPECT_TRUE(client_->silent());
  EXPECT_EQ(bus_->stats().crc_errors, 2u);
  EXPECT_EQ(read_u8(1, xreg::led), 0);
}

TEST_F(DynamixelSimBusTest, UnknownIdGetsNoAnswer) {
  client_->send(test::ping(7));
  client_->send(test::read(9, xreg::present_position, 4));
  EXPECT_TRUE(client_->silent());
  EXPECT_EQ(transact(test::ping(3)).id, 3);  // still serving
}

TEST_F(DynamixelSimBusTest, StrayBytesSplitAndBackToBackPackets) {
  const Bytes p = test::ping(2);
  Bytes noise = {0x00, 0x42, 0xFF, 0x13};
  send_and_wait_read(noise);
  send_and_wait_read(Bytes(p.begin(), p.begin() + 4));
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(30)));
  // After that silence the firmware dropped the half packet: its rest is junk.
  send_and_wait_read(Bytes(p.begin() + 4, p.end()));
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(30)));
  EXPECT_EQ(bus_->stats().partial_packet_bytes, 4u);

  Bytes two = test::ping(1);
  const Bytes r = test::read(3, xreg::present_temperature, 1);
  two.insert(two.end(), r.begin(), r.end());
  client_->send(two);
  const auto answers = client_->read_status(2);
  ASSERT_EQ(answers.size(), 2u);
  EXPECT_EQ(answers[0].id, 1);
  EXPECT_EQ(answers[1].id, 3);
  EXPECT_EQ(answers[1].data, Bytes({36}));
  EXPECT_GE(bus_->stats().stray_bytes, noise.size());
}

TEST_F(DynamixelSimBusTest, HeaderClaimingALongLengthDoesNotSwallowWhatFollowsASilence) {
  // Header, id 1, LEN 0x00FF, then nothing more of that packet.
  send_and_wait_read({0xFF, 0xFF, 0xFD, 0x00, 0x01, 0xFF, 0x00, 0x02});
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(50)));
  const auto s = transact(test::ping(2));
  EXPECT_EQ(s.id, 2);
  EXPECT_EQ(s.error, 0);
  EXPECT_EQ(bus_->stats().partial_packet_bytes, 8u);
}

TEST_F(DynamixelSimBusTest, AnswerDelayMakesTheNextAnswersLate) {
  bus_->set_device_answer_delay(1, 80'000'000, 1);  // 80 ms, one answer
  client_->send(test::ping(1));
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(30)));
  const auto late = client_->read_status(1);
  ASSERT_EQ(late.size(), 1u);
  EXPECT_EQ(late[0].id, 1);
  // Only one answer was delayed; another servo was never affected.
  EXPECT_EQ(transact(test::ping(1)).id, 1);
  EXPECT_THROW(bus_->set_device_answer_delay(9, 1, 1), std::out_of_range);
}

TEST_F(DynamixelSimBusTest, GoalLogKeepsEveryGoalWithItsTimeAndVerdict) {
  clock_.set(1'000'000);
  EXPECT_EQ(write_u32(2, xreg::goal_position, 2100), 0);
  clock_.set(2'000'000);
  EXPECT_EQ(write_u32(2, xreg::goal_position, 5000), err(StatusError::data_limit));
  clock_.set(3'000'000);
  // Sync Write: no answer, so a round trip before looking at the log.
  Bytes params = {static_cast<std::uint8_t>(xreg::goal_position), 0, 4, 0};
  for (std::uint8_t id : {1, 2}) {
    params.push_back(id);
    for (int k = 0; k < 4; ++k) params.push_back(static_cast<std::uint8_t>((2200 + id) >> (8 * k)));
  }
  client_->send(test::packet(dxl::kBroadcastId, dxl::inst::sync_write, params));
  transact(test::ping(3));
  const auto log = bus_->device_goal_log(2);
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log[0].ticks, 2100);
  EXPECT_EQ(log[0].time, 1'000'000);
  EXPECT_TRUE(log[0].accepted);
  EXPECT_EQ(log[1].ticks, 5000);
  EXPECT_FALSE(log[1].accepted);
  EXPECT_EQ(log[2].ticks, 2202);
  EXPECT_TRUE(log[2].accepted);
  EXPECT_DOUBLE_EQ(log[2].rad, config_.actuators[1].to_rad(2202));
  EXPECT_EQ(bus_->device_goals_received(1), 1u);
  EXPECT_TRUE(bus_->device_goal_log(3).empty());
}

TEST_F(DynamixelSimBusTest, EepromWriteWithTorqueOnIsAnAccessError) {
  EXPECT_EQ(write_u8(1, xreg::return_delay_time, 5), 0);  // torque off: allowed
  EXPECT_EQ(read_u8(1, xreg::return_delay_time), 5);
  ASSERT_EQ(write_u8(1, xreg::torque_enable, 1), 0);
  EXPECT_EQ(write_u8(1, xreg::return_delay_time, 10), err(StatusError::access));
  EXPECT_EQ(write_u32(1, xreg::max_position_limit, 3000), err(StatusError::access));
  EXPECT_EQ(read_u8(1, xreg::return_delay_time), 5);
  EXPECT_EQ(read_i32(1, xreg::max_position_limit), 4095);
  // RAM stays writable.
  EXPECT_EQ(write_u8(1, xreg::led, 1), 0);
}

TEST_F(DynamixelSimBusTest, GoalOutsideThePositionLimitsIsADataLimitError) {
  EXPECT_EQ(write_u32(2, xreg::goal_position, 4096), err(StatusError::data_limit));
  EXPECT_EQ(write_u32(2, xreg::goal_position, static_cast<std::uint32_t>(-1)),
            err(StatusError::data_limit));
  EXPECT_EQ(read_i32(2, xreg::goal_position), start_ticks(2));  // not applied

  EXPECT_EQ(write_u32(2, xreg::max_position_limit, 3000), 0);
  EXPECT_EQ(write_u32(2, xreg::min_position_limit, 1000), 0);
  EXPECT_EQ(write_u32(2, xreg::goal_position, 3001), err(StatusError::data_limit));
  EXPECT_EQ(write_u32(2, xreg::goal_position, 999), err(StatusError::data_limit));
  EXPECT_EQ(write_u32(2, xreg::goal_position, 3000), 0);
}

TEST_F(DynamixelSimBusTest, BadAddressOrLengthErrors) {
  // Two bytes of the 4-byte Goal Position: Data Length Error.
  EXPECT_EQ(transact(test::write(1, xreg::goal_position, {0x00, 0x08})).error,
            err(StatusError::data_length));
  // Starting inside an item.
  EXPECT_EQ(transact(test::write(1, xreg::goal_position + 1, {0, 0, 0})).error,
            err(StatusError::data_length));
  // Read-only and undefined addresses: Access Error.
  EXPECT_EQ(write_u32(1, xreg::present_position, 100), err(StatusError::access));
  EXPECT_EQ(write_u8(1, 66, 1), err(StatusError::access));
  // Outside the control table (it ends with Indirect Data 56 at 661).
  EXPECT_EQ(transact(test::read(1, 660, 4)).error, err(StatusError::access));
  EXPECT_EQ(transact(test::write(1, 662, {1})).error, err(StatusError::access));
  // Inside it, a real servo answers: Indirect Address 17 reads 240.
  EXPECT_EQ(transact(test::read(1, 200, 2)).data, Bytes({240, 0}));
  EXPECT_EQ(transact(test::write(1, 200, {1})).error, err(StatusError::data_length));
  // Values outside an item's range: Data Range Error.
  EXPECT_EQ(write_u8(1, xreg::torque_enable, 2), err(StatusError::data_range));
  EXPECT_EQ(write_u8(1, xreg::status_return_level, 3), err(StatusError::data_range));
  EXPECT_EQ(write_u8(1, xreg::operating_mode, 1), err(StatusError::data_range));  // not modelled
  // Malformed parameter blocks.
  EXPECT_EQ(transact(test::packet(1, dxl::inst::read, {0x84, 0x00, 0x04})).error,
            err(StatusError::data_length));
  EXPECT_EQ(transact(test::packet(1, dxl::inst::write, {0x41, 0x00})).error,
            err(StatusError::data_length));
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(20)));
}

TEST_F(DynamixelSimBusTest, UnknownInstructionIsAnInstructionError) {
  const auto s = transact(test::packet(2, 0x7F, {}));
  EXPECT_EQ(s.id, 2);
  EXPECT_EQ(s.error, err(StatusError::instruction));
  // Clear is not modelled (Factory Reset is: servo_commissioning_test.cpp).
  EXPECT_EQ(transact(test::packet(2, dxl::inst::clear, {0x01, 0x44, 0x58, 0x4C, 0x22})).error,
            err(StatusError::instruction));
  // Action without Reg Write, as the manual lists.
  EXPECT_EQ(transact(test::packet(2, dxl::inst::action, {})).error, err(StatusError::instruction));
}

TEST_F(DynamixelSimBusTest, RegWriteWaitsForAction) {
  Bytes params = {0x74, 0x00};
  params.resize(6);
  dxl::put_u32(&params[2], 1234);
  EXPECT_EQ(transact(test::packet(1, dxl::inst::reg_write, params)).error, 0);
  EXPECT_EQ(read_u8(1, xreg_sim::registered_instruction), 1);
  EXPECT_EQ(read_i32(1, xreg::goal_position), start_ticks(1));
  client_->send(test::packet(dxl::kBroadcastId, dxl::inst::action, {}));
  EXPECT_TRUE(client_->silent());
  EXPECT_EQ(read_i32(1, xreg::goal_position), 1234);
  EXPECT_EQ(read_u8(1, xreg_sim::registered_instruction), 0);
}

TEST_F(DynamixelSimBusTest, StatusReturnLevelIsRespected) {
  ASSERT_EQ(write_u8(1, xreg::status_return_level, 1), 0);
  client_->send(test::write(1, xreg::led, {1}));
  EXPECT_TRUE(client_->silent());       // Write: no answer at level 1
  EXPECT_EQ(read_u8(1, xreg::led), 1);  // but applied, and Read answers
  client_->send(test::write(1, xreg::status_return_level, {0}));
  EXPECT_TRUE(client_->silent());
  client_->send(test::read(1, xreg::led, 1));
  EXPECT_TRUE(client_->silent());            // Read: no answer at level 0
  EXPECT_EQ(transact(test::ping(1)).id, 1);  // Ping always answers
  // Broadcast Write never answers, even at level 2.
  ASSERT_EQ(write_u8(2, xreg::led, 1), 0);
  client_->send(test::write(dxl::kBroadcastId, xreg::led, {0}));
  EXPECT_TRUE(client_->silent());
  EXPECT_EQ(read_u8(2, xreg::led), 0);
}

TEST_F(DynamixelSimBusTest, RebootAnswersThenRestoresRam) {
  ASSERT_EQ(write_u8(3, xreg::torque_enable, 1), 0);
  ASSERT_EQ(write_u8(3, xreg::led, 1), 0);
  ASSERT_EQ(write_u8(3, xreg::torque_enable, 0), 0);
  ASSERT_EQ(write_u8(3, xreg::return_delay_time, 7), 0);
  // e-manual Protocol 2.0 Reboot Example is for ID 1; this is the same for ID 3.
  EXPECT_EQ(transact(test::packet(3, dxl::inst::reboot, {})).error, 0);
  EXPECT_EQ(read_u8(3, xreg::led), 0);
  EXPECT_EQ(read_u8(3, xreg::torque_enable), 0);
  EXPECT_EQ(read_u8(3, xreg::return_delay_time), 7);  // EEPROM kept
}

TEST_F(DynamixelSimBusTest, NonRespondingDeviceIsSilent) {
  bus_->set_device_responding(2, false);
  client_->send(test::ping(2));
  EXPECT_TRUE(client_->silent());
  // Sync Read skips it (simplification: the next servo answers at once).
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  const std::uint8_t ids[] = {1, 2, 3};
  const std::size_t n = dxl::encode_sync_read(xreg::present_position, 4, ids, buf);
  client_->send(Bytes(buf.begin(), buf.begin() + n));
  auto answers = client_->read_status(2);
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(200)));
  ASSERT_EQ(answers.size(), 2u);
  EXPECT_EQ(answers[0].id, 1);
  EXPECT_EQ(answers[1].id, 3);
  // It ignores writes too, and comes back when told.
  client_->send(test::write(dxl::kBroadcastId, xreg::led, {1}));
  EXPECT_TRUE(client_->silent());
  bus_->set_device_responding(2, true);
  EXPECT_EQ(read_u8(2, xreg::led), 0);
  EXPECT_EQ(read_u8(3, xreg::led), 1);
  EXPECT_THROW(bus_->set_device_responding(42, false), std::out_of_range);
}

TEST_F(DynamixelSimBusTest, HardwareErrorSetsTheAlertBitAndShutsDown) {
  ASSERT_EQ(write_u8(1, xreg::torque_enable, 1), 0);
  bus_->set_device_hardware_error(1, 0x04);  // overheating: in the default Shutdown mask
  EXPECT_EQ(transact(test::ping(1)).error, dxl::kAlertBit);
  const auto hw = transact(test::read(1, xreg::hardware_error_status, 1));
  EXPECT_EQ(hw.error, dxl::kAlertBit);
  EXPECT_EQ(hw.data, Bytes({0x04}));
  EXPECT_EQ(read_u8(1, xreg::torque_enable), 0);  // shut down
  EXPECT_EQ(write_u8(1, xreg::torque_enable, 1), dxl::kAlertBit | err(StatusError::result_fail));
  EXPECT_EQ(write_u8(1, xreg::led, 1), dxl::kAlertBit);  // other writes still work
  EXPECT_EQ(transact(test::ping(2)).error, 0);           // other servos unaffected

  // Still faulty after a reboot; cleared fault plus reboot brings it back.
  EXPECT_EQ(transact(test::packet(1, dxl::inst::reboot, {})).error, dxl::kAlertBit);
  EXPECT_EQ(write_u8(1, xreg::torque_enable, 1), dxl::kAlertBit | err(StatusError::result_fail));
  bus_->set_device_hardware_error(1, 0);
  EXPECT_EQ(transact(test::ping(1)).error, 0);
  EXPECT_EQ(write_u8(1, xreg::torque_enable, 1), err(StatusError::result_fail));
  EXPECT_EQ(transact(test::packet(1, dxl::inst::reboot, {})).error, 0);
  EXPECT_EQ(write_u8(1, xreg::torque_enable, 1), 0);
}

TEST_F(DynamixelSimBusTest, HardwareErrorOutsideShutdownMaskOnlyAlerts) {
  ASSERT_EQ(write_u8(2, xreg::torque_enable, 1), 0);
  bus_->set_device_hardware_error(2, 0x01);  // input voltage: not in the default mask
  const auto s = transact(test::read(2, xreg::torque_enable, 1));
  EXPECT_EQ(s.error, dxl::kAlertBit);
  EXPECT_EQ(s.data, Bytes({1}));
}

TEST_F(DynamixelSimBusTest, WireTimeHoldsAnswersForTheirBytesOnTheLine) {
  BusConfig slow = make_config({1});
  slow.baud = 57'600;
  slow.sim.wire_time = true;
  slow.sim.return_delay_us = 500;
  open(slow);
  // Ping: 10 bytes out, 500 us delay, 14 bytes back = 24 * 10 / 57600 s + 0.5 ms.
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(transact(test::ping(1)).id, 1);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(elapsed, 24 * 10 / 57600.0 + 500e-6);
  EXPECT_EQ(read_u8(1, xreg::return_delay_time), 250);
}

// Sends `instruction` and reads `sizes` bytes in turn; returns when each
// piece was complete, in seconds after sending.
std::vector<double> arrival_times(PtyClient& client, const Bytes& instruction,
                                  std::initializer_list<std::size_t> sizes) {
  const auto t0 = std::chrono::steady_clock::now();
  client.send(instruction);
  std::vector<double> times;
  for (std::size_t n : sizes) {
    EXPECT_EQ(client.read_raw(n).size(), n);
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return times;
}

TEST_F(DynamixelSimBusTest, WireTimeSendsNoAnswerBeforeItsLastByteCouldArrive) {
  // Answers that are due together may leave in one write, but none before
  // the instruction's and its own bytes (and those before it) have passed.
  BusConfig slow = make_config({1, 2, 3});
  slow.baud = 57'600;
  slow.sim.wire_time = true;
  slow.sim.firmware_version = 46;  // fast read
  open(slow);
  const double byte_s = 10 / 57600.0;
  const std::uint8_t ids[] = {1, 2, 3};
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  const Bytes sync(buf.begin(),
                   buf.begin() + dxl::encode_sync_read(xreg::present_position, 4, ids, buf));
  ASSERT_EQ(sync.size(), 17u);
  const auto sync_times = arrival_times(*client_, sync, {15, 15, 15});
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_GE(sync_times[k], (17 + 15 * (k + 1)) * byte_s) << "answer " << k;
  }
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(20)));

  // Fast Sync Read with the middle servo silent: its slice is left out, and
  // the next one still waits for its own bytes only.
  bus_->set_device_responding(2, false);
  const Bytes fast(buf.begin(),
                   buf.begin() + dxl::encode_fast_sync_read(xreg::present_position, 4, ids, buf));
  const auto fast_times = arrival_times(*client_, fast, {16, 8});
  EXPECT_GE(fast_times[0], (17 + 16) * byte_s);
  EXPECT_GE(fast_times[1], (17 + 24) * byte_s);
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(20)));
}

TEST_F(DynamixelSimBusTest, StopAndStartAgain) {
  bus_->stop();
  client_->send(test::ping(1));
  EXPECT_TRUE(client_->silent(std::chrono::milliseconds(50)));
  bus_->start();
  EXPECT_EQ(client_->read_status(1).size(), 1u);  // the queued ping is served
  bus_->stop();
  bus_->stop();  // idempotent
}

TEST(SimulatedBusFactory, BuildsDynamixelAndRejectsOthers) {
  ManualClock clock;
  BusConfig config = make_config({4});
  auto bus = make_simulated_bus(config, clock);
  ASSERT_NE(bus, nullptr);
  EXPECT_EQ(bus->describe(), "serial legs " + bus->endpoint());

  config.protocol = "canopen";
  EXPECT_THROW(make_simulated_bus(config, clock), InputError);
  config.protocol = "dynamixel2";
  config.actuators.push_back(config.actuators.front());
  EXPECT_THROW(make_simulated_bus(config, clock), InputError);  // id used twice
}

}  // namespace
}  // namespace animrt
