// The runtime's DynamixelBus against the simulated servos: late answers and
// the joint limits the bus writes into the servos' position-limit registers.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/sim/dynamixel_sim_bus.hpp"
#include "sim/pty_client.hpp"

namespace animrt {
namespace {

namespace xreg = dxl::xreg;

std::uint32_t as_u32(const test::Bytes& data) {
  return data.size() == 4 ? dxl::get_u32(data.data()) : 0xFFFFFFFFu;
}

BusConfig two_servos(double timeout_s) {
  BusConfig config;
  config.name = "legs";
  config.protocol = "dynamixel2";
  config.timeout_s = timeout_s;
  for (int id : {3, 4}) {
    ActuatorBinding b;
    b.joint = "joint" + std::to_string(id);
    b.joint_index = id - 3;
    b.device_id = id;
    config.actuators.push_back(b);
  }
  return config;
}

TEST(DynamixelBusOnSim, LateAnswersAreNeverTakenForTheNextRequest) {
  // Timeout T = 100 ms, the servo's first two answers 150 ms late. The first
  // ping times out and its retry takes the late answer (t = 150 ms); the
  // answer to the retry then comes at 300 ms, while the present position is
  // being read for the second time. That 3-byte ping answer, from the right
  // id, must not pass for (or spoil) the 4-byte position that follows it.
  BusConfig config = two_servos(0.1);
  config.actuators.pop_back();  // one servo: the timeline above is exact
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  sim.set_device_answer_delay(3, 150'000'000, 2);
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  ASSERT_NO_THROW(bus.configure());
  std::vector<double> q(1, 99.0);
  bus.read(q);
  EXPECT_NEAR(q[0], sim.device_position(3), 1e-3);
  // The late answers cost timeouts (whether the stale packet was discarded
  // before a request or seen and counted during one depends on scheduling).
  EXPECT_GE(bus.devices()[0].timeouts, 1u);
}

TEST(DynamixelBusOnSim, ServoRefusesGoalsOutsideTheJointLimitsTheBusWrote) {
  BusConfig config = two_servos(0.1);
  config.actuators[0].min_position = -0.3;
  config.actuators[0].max_position = 0.4;
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  bus.configure();
  bus.activate();
  std::vector<double> q(2, 0.0);
  bus.read(q);
  bus.write(std::vector<double>{2.0, 0.0});  // clamped by the bus to 0.4
  bus.read(q);
  const auto log = sim.device_goal_log(3);
  ASSERT_FALSE(log.empty());
  EXPECT_EQ(log.back().ticks, config.actuators[0].to_ticks(0.4));
  for (const auto& g : log) EXPECT_LE(g.rad, 0.4 + 1e-3);

  // Device side: another master writing past the limits is refused.
  bus.deactivate();
  test::PtyClient other(sim.endpoint());
  const std::int32_t hi = config.actuators[0].to_ticks(0.4);
  const std::int32_t lo = config.actuators[0].to_ticks(-0.3);
  EXPECT_EQ(as_u32(other.transact(test::read(3, xreg::max_position_limit, 4)).data),
            static_cast<std::uint32_t>(hi));
  EXPECT_EQ(as_u32(other.transact(test::read(3, xreg::min_position_limit, 4)).data),
            static_cast<std::uint32_t>(lo));
  EXPECT_EQ(
      other.transact(test::write_u32(3, xreg::goal_position, static_cast<std::uint32_t>(hi + 50)))
          .error,
      static_cast<std::uint8_t>(dxl::StatusError::data_limit));
  EXPECT_EQ(
      other.transact(test::write_u32(3, xreg::goal_position, static_cast<std::uint32_t>(hi))).error,
      0);
  // The joint without limits keeps the full range.
  EXPECT_EQ(as_u32(other.transact(test::read(4, xreg::max_position_limit, 4)).data), 4095u);
}

}  // namespace
}  // namespace animrt
