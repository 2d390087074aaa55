// The runtime's FeetechBus against the simulated servo board over a real
// pseudo-terminal: the lifecycle, the cycle for both series, negative
// positions through the sign bit, and a servo that stops answering or
// reports a fault.

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/feetech/feetech_bus.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/sim/feetech/feetech_sim_bus.hpp"

namespace animrt {
namespace {

// The timeout leaves a loaded machine room to run the simulated servos'
// thread: answers come at once, so only a silent servo waits it out.
BusConfig arm(ft::Series series, std::initializer_list<int> ids, double timeout_s = 0.3) {
  BusConfig config;
  config.name = "arm";
  config.protocol = series == ft::Series::sts ? "feetech_sts" : "feetech_scs";
  config.timeout_s = timeout_s;
  int index = 0;
  for (int id : ids) {
    ActuatorBinding b;
    b.joint = "joint" + std::to_string(id);
    b.joint_index = index++;
    b.device_id = id;
    b.ticks_per_rad =
        (series == ft::Series::sts ? ft::kStsStepsPerRev : ft::kScsStepsPerRev) / (2.0 * kPi);
    b.zero_ticks = series == ft::Series::sts ? 2048 : 512;
    config.actuators.push_back(b);
  }
  return config;
}

struct Fixture {
  Fixture(const BusConfig& c, ft::Series series)
      : config(c),
        sim(c, series, clock),
        bus((sim.start(), c), series, open_serial(sim.endpoint(), c.baud)) {}
  ManualClock clock{0};
  BusConfig config;
  sim::FeetechSimBus sim;
  FeetechBus bus;
};

void run_cycle(Fixture& f, ft::Series series) {
  f.bus.configure();
  std::vector<double> q(2, 99.0);
  f.bus.read(q);  // what configure() read: the servos' start positions
  const double tick = 2 * kPi / (series == ft::Series::sts ? 4096.0 : ft::kScsStepsPerRev);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(q[i], f.sim.device_position(f.config.actuators[i].device_id), tick);
    EXPECT_GT(std::abs(q[i]), 0.01);  // the board starts its servos off zero
  }
  f.bus.activate();
  const std::vector<double> goal = {0.3, -0.2};
  f.bus.write(goal);
  f.bus.read(q);  // answered: the Sync Write before it has taken effect
  f.clock.advance(3'000'000'000);
  f.bus.read(q);
  EXPECT_NEAR(q[0], 0.3, tick);
  EXPECT_NEAR(q[1], -0.2, tick);
  for (const DeviceStatus& st : f.bus.devices()) {
    EXPECT_EQ(st.health, DeviceHealth::ok);
    EXPECT_EQ(st.timeouts, 0u);
    EXPECT_EQ(st.crc_errors, 0u);
    EXPECT_EQ(st.protocol_errors, 0u);
    EXPECT_EQ(st.hardware_errors, 0u);
    // ping, read, goal write, torque on, 3 cycle reads
    EXPECT_EQ(st.transactions, 7u);
  }
  f.bus.deactivate();
  f.clock.advance(1'000'000'000);
  EXPECT_NEAR(f.sim.device_position(f.config.actuators[0].device_id), 0.3, tick);
}

TEST(FeetechBusOnSim, StsBusConfiguresActivatesAndTracks) {
  Fixture f(arm(ft::Series::sts, {1, 2}), ft::Series::sts);
  run_cycle(f, ft::Series::sts);
  EXPECT_GE(f.sim.device_goals_received(2), 2u);  // activate's write + the Sync Write
}

TEST(FeetechBusOnSim, ScsBusReadsEachServoInTurn) {
  Fixture f(arm(ft::Series::scs, {3, 4}), ft::Series::scs);
  run_cycle(f, ft::Series::scs);
  // Big-endian goals arrive as the steps the binding computes.
  EXPECT_EQ(f.sim.device_last_goal(4), f.config.actuators[1].to_ticks(-0.2));
}

TEST(FeetechBusOnSim, NegativePositionsRoundTripThroughTheSignBit) {
  // zero_ticks 0: every negative angle is a negative step count, written
  // and read back sign-magnitude (bit 15). Angle limits 0/0 put the servo
  // in multi-turn mode, where it takes such goals.
  BusConfig config = arm(ft::Series::sts, {1});
  config.actuators[0].zero_ticks = 0;
  Fixture f(config, ft::Series::sts);
  {
    auto line = open_serial(f.sim.endpoint(), 1'000'000);
    std::array<std::uint8_t, ft::kMaxPacket> tx{};
    const std::uint8_t zero[2] = {0, 0};
    line->write({tx.data(), ft::encode_write(1, ft::reg::max_angle_limit, zero, tx)});
    std::array<std::uint8_t, 16> ack{};
    line->read(ack, std::chrono::milliseconds(500));
  }
  f.bus.configure();
  f.bus.activate();
  std::vector<double> q(1, 0.0);
  f.bus.read(q);
  f.bus.write(std::vector<double>{-1.0});
  f.bus.read(q);
  EXPECT_EQ(f.sim.device_last_goal(1), f.config.actuators[0].to_ticks(-1.0));
  EXPECT_LT(f.sim.device_last_goal(1), -600);
  f.clock.advance(3'000'000'000);
  f.bus.read(q);
  EXPECT_NEAR(q[0], -1.0, 2 * kPi / 4096);
}

TEST(FeetechBusOnSim, ServoKeepsGoalsInsideTheJointLimitsTheBusWrote) {
  for (ft::Series series : {ft::Series::sts, ft::Series::scs}) {
    BusConfig config = arm(series, {1, 2});
    config.actuators[0].min_position = -0.3;
    config.actuators[0].max_position = 0.4;
    config.actuators[0].direction = -1;  // the limits swap ends in steps
    Fixture f(config, series);
    f.bus.configure();
    const ActuatorBinding& b = f.config.actuators[0];
    // Read back over the wire by another client: Min/Max Angle Limit.
    auto line = open_serial(f.sim.endpoint(), 1'000'000);
    std::array<std::uint8_t, ft::kMaxPacket> tx{};
    std::array<std::uint8_t, 32> rx{};
    // Collects `n` answer bytes (or what came within five seconds).
    const auto answer = [&](std::size_t n) {
      std::size_t got = 0;
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      while (got < n && std::chrono::steady_clock::now() < deadline) {
        got += line->read(std::span(rx).subspan(got, n - got), std::chrono::milliseconds(50));
      }
      return got;
    };
    line->write({tx.data(), ft::encode_read(1, ft::reg::min_angle_limit, 4, tx)});
    ASSERT_EQ(answer(10), 10u);
    EXPECT_EQ(ft::get_u16(series, &rx[5]), b.to_ticks(0.4));  // direction -1: the low end
    EXPECT_EQ(ft::get_u16(series, &rx[7]), b.to_ticks(-0.3));
    // The servo itself stops at the limit whatever goal it is given.
    std::uint8_t goal[2];
    ft::put_u16(series, goal, series == ft::Series::sts ? 4000 : 1000);
    const std::uint8_t on = 1;
    line->write({tx.data(), ft::encode_write(1, ft::reg::torque_enable, {&on, 1}, tx)});
    ASSERT_EQ(answer(6), 6u);
    line->write({tx.data(), ft::encode_write(1, ft::reg::goal_position, goal, tx)});
    ASSERT_EQ(answer(6), 6u);
    f.clock.advance(3'000'000'000);
    EXPECT_NEAR(f.sim.device_position(1), -0.3, 0.01);
    // The joint without limits keeps the whole range.
    line->write({tx.data(), ft::encode_read(2, ft::reg::max_angle_limit, 2, tx)});
    ASSERT_EQ(answer(8), 8u);
    EXPECT_EQ(ft::get_u16(series, &rx[5]),
              series == ft::Series::sts ? ft::kStsMaxPosition : ft::kScsMaxPosition);
  }
}

// A servo that rests outside its joint's limits (a hanging jaw) must not
// snap to the nearest limit when torque comes on: the servo clamps its goal
// into its angle limits, so the bus widens them to where the joint is, warns,
// and leads the goals in from there.
TEST(FeetechBusOnSim, JointRestingOutsideItsLimitsStartsAndIsLedInside) {
  for (ft::Series series : {ft::Series::sts, ft::Series::scs}) {
    SCOPED_TRACE(series == ft::Series::sts ? "sts" : "scs");
    const BusConfig device_side = arm(series, {3, 4});  // the board knows no joint limits
    BusConfig config = device_side;
    config.actuators[1].min_position = 0.0;
    config.actuators[1].max_position = 0.5;
    const ActuatorBinding& jaw = config.actuators[1];
    ManualClock clock{0};
    sim::FeetechSimBus sim(device_side, series, clock);
    sim.start();
    const double rest = sim.device_position(4);
    ASSERT_LT(rest, -0.04);
    FeetechBus bus(config, series, open_serial(sim.endpoint(), config.baud));
    ASSERT_NO_THROW(bus.configure());
    EXPECT_NE(bus.outside_warning().find("id 4 (joint4) is at -"), std::string::npos)
        << bus.outside_warning();
    EXPECT_NE(bus.outside_warning().find("outside its limits 0.0..28.6 deg"), std::string::npos)
        << bus.outside_warning();
    ASSERT_NO_THROW(bus.activate());
    // Torque on holds the joint where it rests.
    clock.advance(1'000'000'000);
    std::vector<double> q(2, 0.0);
    bus.read(q);
    const double tick = 2 * kPi / (series == ft::Series::sts ? 4096.0 : ft::kScsStepsPerRev);
    EXPECT_NEAR(q[1], rest, 1.5 * tick);
    EXPECT_NEAR(sim.device_position(4), rest, 1.5 * tick);

    // Goals farther out than the rest pose are held at it; on the way in, a
    // goal never goes back out past one already sent; inside, the limits rule.
    const std::vector<double> wanted = {rest - 0.2, rest / 2, rest, 0.1, -0.3, 0.7};
    const std::vector<double> sent = {rest, rest / 2, rest / 2, 0.1, 0.0, 0.5};
    for (std::size_t k = 0; k < wanted.size(); ++k) {
      const std::uint64_t before = sim.device_goals_received(4);
      bus.write(std::vector<double>{0.0, wanted[k]});
      bus.read(q);  // a round trip: the board has handled the write
      ASSERT_EQ(sim.device_goals_received(4), before + 1) << "goal " << k;
      EXPECT_EQ(sim.device_last_goal(4), jaw.to_ticks(sent[k])) << "goal " << k;
    }
    clock.advance(3'000'000'000);
    bus.read(q);
    EXPECT_NEAR(q[1], 0.5, 1.5 * tick);

    // Back inside, the next bring-up writes the joint's own limits again.
    bus.deactivate();
    bus.configure();
    EXPECT_TRUE(bus.outside_warning().empty()) << bus.outside_warning();
  }
}

TEST(FeetechBusOnSim, ASilentServoIsCountedAndTheOthersStillServed) {
  Fixture f(arm(ft::Series::sts, {1, 2}), ft::Series::sts);
  f.bus.configure();
  f.bus.activate();
  std::vector<double> q(2, 0.0);
  f.bus.read(q);
  f.sim.set_device_responding(2, false);
  const double held = q[1];
  f.bus.write(std::vector<double>{0.1, 0.1});
  f.clock.advance(2'000'000'000);
  for (int k = 0; k < 3; ++k) f.bus.read(q);
  EXPECT_EQ(f.bus.devices()[1].timeouts, 3u);
  EXPECT_EQ(f.bus.devices()[1].health, DeviceHealth::timeout);
  EXPECT_EQ(q[1], held);  // unchanged, never made up
  EXPECT_EQ(f.bus.devices()[0].timeouts, 0u);
  EXPECT_NEAR(q[0], 0.1, 2 * kPi / 4096);
  // Once faulted (by the runtime's watchdog) it is no longer asked.
  f.bus.mark_faulted(1);
  f.bus.read(q);
  EXPECT_EQ(f.bus.devices()[1].timeouts, 3u);
  EXPECT_EQ(f.bus.devices()[0].timeouts, 0u);
}

TEST(FeetechBusOnSim, ScsSilentServoCostsOnlyItsOwnRead) {
  Fixture f(arm(ft::Series::scs, {1, 2, 3}), ft::Series::scs);
  f.bus.configure();
  f.bus.activate();
  f.sim.set_device_responding(2, false);
  std::vector<double> q(3, 0.0);
  f.bus.write(std::vector<double>{0.1, 0.1, -0.1});
  f.clock.advance(2'000'000'000);
  f.bus.read(q);
  EXPECT_EQ(f.bus.devices()[1].timeouts, 1u);
  EXPECT_EQ(f.bus.devices()[0].health, DeviceHealth::ok);
  EXPECT_EQ(f.bus.devices()[2].health, DeviceHealth::ok);
  EXPECT_NEAR(q[2], -0.1, 2 * kPi / ft::kScsStepsPerRev);
}

TEST(FeetechBusOnSim, ConfigureNamesTheServoThatDoesNotAnswer) {
  Fixture f(arm(ft::Series::sts, {1, 2}, 0.1), ft::Series::sts);
  f.sim.set_device_responding(2, false);
  try {
    f.bus.configure();
    FAIL() << "configure() did not throw";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no answer to ping from id 2 (joint2)"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(f.bus.devices()[1].timeouts,
            static_cast<std::uint64_t>(FeetechBus::kTries * kPingRounds));
}

TEST(FeetechBusOnSim, FaultBitsInTheErrorByteAreHardwareErrors) {
  Fixture f(arm(ft::Series::sts, {1, 2}), ft::Series::sts);
  f.bus.configure();
  f.bus.activate();
  f.sim.set_device_hardware_error(1, ft::error_bit::overload);
  std::vector<double> q(2, 0.0);
  f.bus.read(q);
  const DeviceStatus& st = f.bus.devices()[0];
  EXPECT_EQ(st.health, DeviceHealth::hardware_error);
  EXPECT_EQ(st.hardware_errors, 1u);
  EXPECT_EQ(st.hardware_error_status, ft::error_bit::overload);
  EXPECT_EQ(f.bus.devices()[1].health, DeviceHealth::ok);
  // A servo in a fault refuses to be started.
  f.bus.deactivate();
  EXPECT_THROW(f.bus.activate(), DeviceError);
}

}  // namespace
}  // namespace animrt
