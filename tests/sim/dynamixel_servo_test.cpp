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

}  // namespace
}  // namespace animrt::sim
