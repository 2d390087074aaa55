// The BNO08x UART-RVC reader against the simulated part on a real
// pseudo-terminal: the scripted push arrives in the trunk's frame whatever
// the part's mounting, with its rate, and the stream counts no errors.

#include "animrt/bridge/imu/rvc_reader.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <numbers>
#include <thread>

#include "animrt/sim/imu/rvc_sim_imu.hpp"

namespace animrt::rvc_reader_test {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

ImuConfig pushed_imu() {
  ImuConfig c;
  c.name = "trunk";
  c.protocol = "bno08x_rvc";
  c.sim_push.on = true;
  c.sim_push.at_s = 0.1;
  c.sim_push.rate_rad_s = 90 * kDeg;
  c.sim_push.to_rad = 80 * kDeg;
  return c;
}

// Takes readings until the roll passes `roll` (or 5 s of wall time).
ImuReading wait_for_roll(imu::RvcReader& reader, double roll, int& taken) {
  ImuReading r;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < until) {
    if (reader.readings().take(r)) {
      ++taken;
      if (roll_of(r.quat) >= roll) return r;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return r;
}

void expect_push_arrives(const ImuConfig& config) {
  const MonotonicClock clock;
  const Nanos start = clock.now();
  sim::RvcSimImu part(config, clock, start, sim::scripted_trunk(config.sim_push));
  imu::RvcReader reader(open_serial(part.port(), 115200), config, clock, start);
  int taken = 0;
  const ImuReading r = wait_for_roll(reader, 45 * kDeg, taken);
  ASSERT_GE(roll_of(r.quat), 45 * kDeg);
  EXPECT_NEAR(pitch_of(r.quat), 0.0, 0.02 * kDeg);
  EXPECT_NEAR(yaw_of(r.quat), 0.0, 0.02 * kDeg);
  // Rolling at 90 deg/s about the trunk's x axis.
  EXPECT_NEAR(r.rate_rad_s[0], 90 * kDeg, 5 * kDeg);
  EXPECT_NEAR(r.rate_rad_s[1], 0.0, 5 * kDeg);
  // The part at rest feels +1 g along the world's up, seen in the trunk frame.
  const TrunkUp up = trunk_up(r.quat);
  EXPECT_NEAR(r.accel_m_s2[1], 9.80665 * up.left_up, 0.02);
  EXPECT_NEAR(r.accel_m_s2[2], 9.80665 * up.up_up, 0.02);
  EXPECT_GT(taken, 10);
  EXPECT_EQ(reader.checksum_errors(), 0u);
}

TEST(RvcReader, AScriptedPushArrivesInTheTrunksFrame) { expect_push_arrives(pushed_imu()); }

TEST(RvcReader, ThePartsMountingIsTakenOut) {
  ImuConfig c = pushed_imu();
  c.mount_ypr_rad = {90 * kDeg, 0.0, 180 * kDeg};  // turned and upside down
  expect_push_arrives(c);
}

}  // namespace
}  // namespace animrt::rvc_reader_test
