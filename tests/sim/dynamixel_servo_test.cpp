// One simulated servo without a pty: the motor model's closed form and the
// firmware's write rules.

#include "animrt/sim/dynamixel_servo.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace animrt::sim {
namespace {

using dxl::StatusError;
namespace xreg = dxl::xreg;

ActuatorBinding binding(int id, int direction = 1) {
  ActuatorBinding b;
  b.joint = "j";
  b.device_id = id;
  b.direction = direction;
  return b;
}

std::int32_t present(const DynamixelServo& s) {
  std::uint8_t data[4];
  EXPECT_EQ(s.read(xreg::present_position, 4, data), StatusError::none);
  return static_cast<std::int32_t>(dxl::get_u32(data));
}

void set_goal(DynamixelServo& s, std::int32_t goal) {
  std::uint8_t data[4];
  dxl::put_u32(data, static_cast<std::uint32_t>(goal));
  ASSERT_EQ(s.write(xreg::goal_position, data), StatusError::none);
}

TEST(DynamixelSimServo, ResultDoesNotDependOnHowOftenItIsAdvanced) {
  // Packets arrive at any rate; the motor state at a time must not care.
  SimBusSettings settings;
  DynamixelServo coarse(binding(1), settings, 1'000'000, 0);
  DynamixelServo fine(binding(1), settings, 1'000'000, 0);
  const std::uint8_t on = 1;
  for (DynamixelServo* s : {&coarse, &fine}) {
    ASSERT_EQ(s->write(xreg::torque_enable, {&on, 1}), StatusError::none);
    set_goal(*s, 3500);
  }
  for (Nanos t = 1'000'000; t <= 400'000'000; t += 1'000'000) fine.advance(t);
  coarse.advance(400'000'000);
  EXPECT_NEAR(fine.position_rad(400'000'000), coarse.position_rad(400'000'000), 1e-9);
  EXPECT_EQ(present(fine), present(coarse));
  // position_rad looks ahead without changing the state.
  const double ahead = coarse.position_rad(500'000'000);
  coarse.advance(500'000'000);
  EXPECT_DOUBLE_EQ(coarse.position_rad(500'000'000), ahead);
}

TEST(DynamixelSimServo, DirectionAndZeroOfTheBinding) {
  SimBusSettings settings;
  DynamixelServo reversed(binding(1, -1), settings, 1'000'000, 0);
  // +3 degrees of joint = fewer ticks when reversed.
  EXPECT_LT(present(reversed), 2048);
  EXPECT_NEAR(reversed.position_rad(0), initial_offset_rad(1), 1e-3);
}

TEST(DynamixelSimServo, PureRateLimitWithoutLag) {
  SimBusSettings settings;
  settings.time_constant_s = 0;
  settings.max_speed_rad_s = 1.0;
  DynamixelServo s(binding(3), settings, 1'000'000, 0);
  const std::uint8_t on = 1;
  ASSERT_EQ(s.write(xreg::torque_enable, {&on, 1}), StatusError::none);
  const std::int32_t start = present(s);
  set_goal(s, start + 100);
  s.advance(from_seconds(0.1));  // 1 rad/s = 65.2 ticks in 0.1 s
  EXPECT_NEAR(present(s), start + 65, 1);
  s.advance(from_seconds(1.0));
  EXPECT_EQ(present(s), start + 100);
}

TEST(DynamixelSimServo, AtomicWriteChangesNothingOnError) {
  SimBusSettings settings;
  DynamixelServo s(binding(2), settings, 57'600, 0);
  // Torque Enable ok but LED out of range: neither is applied.
  const std::uint8_t both[] = {1, 2};
  EXPECT_EQ(s.write(xreg::torque_enable, both), StatusError::data_range);
  EXPECT_FALSE(s.torque_on());
  std::uint8_t baud = 0;
  ASSERT_EQ(s.read(xreg::baud_rate, 1, {&baud, 1}), StatusError::none);
  EXPECT_EQ(baud, 1);  // 57600
}

TEST(DynamixelSimServo, BaudRateRegisterAndOffsets) {
  EXPECT_EQ(baud_rate_register(9600), 0);
  EXPECT_EQ(baud_rate_register(57'600), 1);
  EXPECT_EQ(baud_rate_register(115'200), 2);
  EXPECT_EQ(baud_rate_register(1'000'000), 3);
  EXPECT_EQ(baud_rate_register(4'500'000), 7);
  EXPECT_EQ(baud_rate_register(1'100'000), 3);  // nearest
  for (int id = 0; id < 10; ++id) {
    const double degrees = initial_offset_rad(id) * 180.0 / 3.14159265358979323846;
    EXPECT_GE(std::abs(degrees), 2.0 - 1e-9);
    EXPECT_LE(std::abs(degrees), 4.0 + 1e-9);
  }
}

TEST(DynamixelSimServo, StartsInsideTheJointLimitsOfItsBinding) {
  // id 4 starts 3 degrees below zero; a jaw of 0..30 degrees forbids that.
  ActuatorBinding jaw = binding(4);
  ASSERT_LT(initial_offset_rad(4), 0.0);
  DynamixelServo free(jaw, {}, 1'000'000, 0);
  EXPECT_EQ(present(free), jaw.to_ticks(initial_offset_rad(4)));
  jaw.min_position = 0.0;
  jaw.max_position = 30.0 * 3.14159265358979323846 / 180.0;
  DynamixelServo limited(jaw, {}, 1'000'000, 0);
  EXPECT_EQ(present(limited), jaw.to_ticks(0.0));
  EXPECT_DOUBLE_EQ(initial_position_rad(jaw), 0.0);
  // Limits that hold the offset leave it alone.
  jaw.min_position = -0.5;
  EXPECT_DOUBLE_EQ(initial_position_rad(jaw), initial_offset_rad(4));
}

// ---------------------------------------------------------- Bus Watchdog

std::uint8_t reg8(const DynamixelServo& s, std::uint16_t address) {
  std::uint8_t v = 0;
  EXPECT_EQ(s.read(address, 1, {&v, 1}), StatusError::none);
  return v;
}

TEST(DynamixelSimServo, BusWatchdogStopsTheServoWhenTheHostGoesSilent) {
  SimBusSettings settings;  // 6 rad/s: 4095 ticks take about a second
  DynamixelServo s(binding(1), settings, 1'000'000, 0);
  const std::uint8_t on = 1, units = 3;  // 60 ms
  ASSERT_EQ(s.write(xreg::torque_enable, {&on, 1}), StatusError::none);
  ASSERT_EQ(s.write(xreg::bus_watchdog, {&units, 1}), StatusError::none);
  s.feed_watchdog(0);
  set_goal(s, 4000);
  // Fed at 50 ms: still moving at 100 ms.
  s.advance(50'000'000);
  s.feed_watchdog(50'000'000);
  s.advance(100'000'000);
  EXPECT_EQ(reg8(s, xreg::bus_watchdog), units);
  EXPECT_EQ(reg8(s, xreg::moving), 1);
  // Silent from 50 ms: it stops at 110 ms where it was then, torque on.
  const double at_fire = s.position_rad(110'000'000);
  s.advance(300'000'000);
  EXPECT_EQ(reg8(s, xreg::bus_watchdog), dxl::kBusWatchdogFired);
  EXPECT_EQ(reg8(s, xreg::moving), 0);
  EXPECT_EQ(reg8(s, xreg::torque_enable), 1);
  EXPECT_NEAR(s.position_rad(300'000'000), at_fire, 1e-3);
  EXPECT_LT(present(s), 3000);  // nowhere near the goal
  std::uint8_t velocity[4];
  ASSERT_EQ(s.read(xreg::present_velocity, 4, velocity), StatusError::none);
  EXPECT_EQ(dxl::get_u32(velocity), 0u);
  const std::int32_t held = present(s);
  s.advance(900'000'000);
  EXPECT_EQ(present(s), held);

  // Goals are refused until 0 is written to 98; another value does not clear it.
  std::uint8_t goal[4];
  dxl::put_u32(goal, 4000);
  EXPECT_EQ(s.write(xreg::goal_position, goal), StatusError::data_range);
  EXPECT_EQ(s.write(xreg::bus_watchdog, {&units, 1}), StatusError::data_range);
  EXPECT_EQ(reg8(s, xreg::bus_watchdog), dxl::kBusWatchdogFired);
  const std::uint8_t zero = 0;
  ASSERT_EQ(s.write(xreg::bus_watchdog, {&zero, 1}), StatusError::none);
  EXPECT_EQ(s.write(xreg::goal_position, goal), StatusError::none);
  s.advance(1'000'000'000);
  EXPECT_GT(present(s), held);  // moves again, and no watchdog is armed
  s.advance(3'000'000'000);
  EXPECT_EQ(reg8(s, xreg::bus_watchdog), 0);
}

TEST(DynamixelSimServo, BusWatchdogWatchesOnlyWhileTorqueIsOn) {
  SimBusSettings settings;
  DynamixelServo s(binding(1), settings, 1'000'000, 0);
  const std::uint8_t units = 1, on = 1;
  ASSERT_EQ(s.write(xreg::bus_watchdog, {&units, 1}), StatusError::none);
  s.feed_watchdog(0);
  s.advance(500'000'000);
  EXPECT_EQ(reg8(s, xreg::bus_watchdog), units);  // torque off: nothing to stop
  ASSERT_EQ(s.write(xreg::torque_enable, {&on, 1}), StatusError::none);
  s.feed_watchdog(500'000'000);
  s.advance(519'000'000);
  EXPECT_EQ(reg8(s, xreg::bus_watchdog), units);
  s.advance(521'000'000);
  EXPECT_EQ(reg8(s, xreg::bus_watchdog), dxl::kBusWatchdogFired);
}

}  // namespace
}  // namespace animrt::sim
