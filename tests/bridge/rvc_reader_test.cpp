// The BNO08x UART-RVC reader against the simulated part on a real
// pseudo-terminal: the scripted push arrives in the trunk's frame whatever
// the part's mounting, with its rate, every frame is read, and the stream
// counts no errors.

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

// The next reading, waited for by its arrival. The wall clock only guards
// against a reader that never posts: generous, as the kernel moves a pty's
// bytes on a worker thread of normal priority, which a loaded machine has
// been seen to hold back for over 2 s.
bool take_next(imu::RvcReader& reader, ImuReading& r) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < until) {
    if (reader.readings().take(r)) return true;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return false;
}

// The part and the reader on a lockstep clock stepped one frame at a time,
// each frame's reading taken before the next is due, so what is read
// follows from what was sent however busy the machine is.
void expect_push_arrives(const ImuConfig& config) {
  const Nanos period = from_seconds(1.0 / config.rate_hz);
  const Nanos start = 0;
  // Before the first frame's time until the reader listens (it drops what waited).
  ManualClock clock(start - 1);
  sim::RvcSimImu part(config, clock, start, sim::scripted_trunk(config.sim_push));
  imu::RvcReader reader(open_serial(part.port(), 115200), config, clock, start);
  int taken = 0;
  ImuReading r;
  for (Nanos t = start; t < start + from_seconds(1.0); t += period) {
    clock.set(t);
    ASSERT_TRUE(take_next(reader, r))
        << "no reading for the frame at " << to_seconds(t) << " s (" << part.frames_sent()
        << " frames sent, " << reader.frames() << " read, " << reader.checksum_errors()
        << " checksum errors)";
    ++taken;
    // Stamped when it arrived: the frame's own time, as the clock waits for it.
    ASSERT_DOUBLE_EQ(r.time_s, to_seconds(t - start));
    if (roll_of(r.quat) >= 45 * kDeg) break;
  }
  ASSERT_GE(roll_of(r.quat), 45 * kDeg);
  // Pushed at 0.1 s, rolling at 90 deg/s: 45 deg at 0.6 s.
  EXPECT_NEAR(r.time_s, 0.6, 1.5 * to_seconds(period));
  EXPECT_NEAR(pitch_of(r.quat), 0.0, 0.02 * kDeg);
  EXPECT_NEAR(yaw_of(r.quat), 0.0, 0.02 * kDeg);
  // Rolling at 90 deg/s about the trunk's x axis.
  EXPECT_NEAR(r.rate_rad_s[0], 90 * kDeg, 5 * kDeg);
  EXPECT_NEAR(r.rate_rad_s[1], 0.0, 5 * kDeg);
  // The part at rest feels +1 g along the world's up, seen in the trunk frame.
  const TrunkUp up = trunk_up(r.quat);
  EXPECT_NEAR(r.accel_m_s2[1], 9.80665 * up.left_up, 0.02);
  EXPECT_NEAR(r.accel_m_s2[2], 9.80665 * up.up_up, 0.02);
  // One frame decoded per reading, none missing from the part's count.
  EXPECT_EQ(reader.frames(), static_cast<std::uint64_t>(taken));
  EXPECT_EQ(reader.lost_frames(), 0u);
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
