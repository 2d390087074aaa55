// The runtime's DynamixelBus against the simulated servos: late answers and
// the joint limits the bus writes into the servos' position-limit registers.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
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

TEST(DynamixelBusOnSim, ALifecycleStepOutwaitsAStallOfAFewTimeouts) {
  // Timeout T = 40 ms; the answer to activate's goal-position write leaves
  // 4 T late (as when a busy host does not carry the line's bytes), and the
  // answers to its retries queue behind it. Three tries of T each (3 T) would
  // give up; the retries waiting 2 T and 4 T (7 T in all) take it.
  BusConfig config = two_servos(0.04);
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  ASSERT_NO_THROW(bus.configure());
  sim.set_device_answer_delay(3, 160'000'000, 1);
  ASSERT_NO_THROW(bus.activate());
  EXPECT_TRUE(sim.servo_readout(3).torque);
  EXPECT_GE(bus.devices()[0].timeouts, 1u);  // the first try did time out
  bus.deactivate();

  // A servo that stays silent is still refused, with torque left off.
  sim.set_device_responding(3, false);
  try {
    bus.activate();
    ADD_FAILURE() << "activate took a silent servo";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no answer"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(sim.servo_readout(3).torque);
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
  bus.arm_device_guard();
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

TEST(DynamixelBusOnSim, JointRestingOutsideItsLimitsStartsAndIsLedInside) {
  // The servo rests at 3 degrees below zero (the simulator knows no limits
  // here, as a figure's hanging jaw does not); the bus is told 0..0.5 rad.
  BusConfig device_side = two_servos(0.1);
  BusConfig config = device_side;
  config.actuators[1].min_position = 0.0;
  config.actuators[1].max_position = 0.5;
  const ActuatorBinding& jaw = config.actuators[1];
  ManualClock clock{0};
  sim::DynamixelSimBus sim(device_side, clock);
  sim.start();
  const double rest = sim.device_position(4);
  ASSERT_LT(rest, -0.04);
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  ASSERT_NO_THROW(bus.configure());
  EXPECT_NE(bus.outside_warning().find("id 4 (joint4) is at -3.0 deg"), std::string::npos)
      << bus.outside_warning();
  ASSERT_NO_THROW(bus.activate());
  ASSERT_NO_THROW(bus.arm_device_guard());
  std::vector<double> q(2, 0.0);
  bus.read(q);
  EXPECT_NEAR(q[1], rest, 1e-3);

  // Goals farther out than the rest pose are held at it; on the way in, a
  // goal never goes back out past one already sent; inside, the limits rule.
  const std::vector<double> wanted = {-0.2, -0.02, -0.04, 0.1, -0.3, 0.7};
  const std::vector<double> sent = {rest, -0.02, -0.02, 0.1, 0.0, 0.5};
  const std::uint64_t before = sim.device_goals_received(4);
  for (double w : wanted) {
    bus.write(std::vector<double>{0.0, w});
    bus.read(q);  // a round trip: the servo has handled the write
  }
  ASSERT_EQ(sim.device_goals_received(4) - before, sent.size());
  const auto log = sim.device_goal_log(4);
  ASSERT_GE(log.size(), sent.size());
  for (std::size_t k = 0; k < sent.size(); ++k) {
    const sim::GoalRecord& g = log[log.size() - sent.size() + k];
    EXPECT_EQ(g.ticks, jaw.to_ticks(sent[k])) << "goal " << k;
    EXPECT_TRUE(g.accepted) << "goal " << k;
  }
  EXPECT_EQ(bus.devices()[1].protocol_errors, 0u);

  // Back inside, the next bring-up writes the joint's own limits again.
  clock.advance(2'000'000'000);
  bus.read(q);
  EXPECT_NEAR(q[1], 0.5, 0.01);
  bus.deactivate();
  bus.configure();
  EXPECT_TRUE(bus.outside_warning().empty()) << bus.outside_warning();
  test::PtyClient other(sim.endpoint());
  EXPECT_EQ(as_u32(other.transact(test::read(4, xreg::min_position_limit, 4)).data),
            static_cast<std::uint32_t>(jaw.to_ticks(0.0)));
}

// ---------------------------------------------------------- Bus Watchdog

BusConfig guarded(std::uint8_t units) {
  BusConfig config = two_servos(0.1);
  dxl::BusOptions options;
  options.bus_watchdog = units;
  config.options = options;
  return config;
}

std::uint32_t reg8(test::PtyClient& client, std::uint8_t id, std::uint16_t address) {
  const test::Status st = client.transact(test::read(id, address, 1));
  return st.data.size() == 1 ? st.data[0] : 0xFFFFFFFFu;
}

TEST(DynamixelBusOnSim, BusWatchdogIsSetAtActivateAndClearedAtDeactivate) {
  const BusConfig config = guarded(3);
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  bus.configure();
  test::PtyClient other(sim.endpoint());
  EXPECT_EQ(reg8(other, 3, xreg::bus_watchdog), 0u);
  bus.activate();
  bus.arm_device_guard();
  for (int id : {3, 4}) {
    EXPECT_EQ(reg8(other, static_cast<std::uint8_t>(id), xreg::torque_enable), 1u);
    EXPECT_EQ(reg8(other, static_cast<std::uint8_t>(id), xreg::bus_watchdog), 3u);
  }
  bus.deactivate();
  for (int id : {3, 4}) {
    EXPECT_EQ(reg8(other, static_cast<std::uint8_t>(id), xreg::bus_watchdog), 0u);
    EXPECT_EQ(reg8(other, static_cast<std::uint8_t>(id), xreg::torque_enable), 0u);
  }
}

TEST(DynamixelBusOnSim, BusWatchdogStartsOnlyWhenEveryBusIsUp) {
  // Other buses may take longer to come up than the guard's time: the servos
  // must not count that (they would stop and refuse goals from the first
  // cycle on), and arming reaches every servo at once.
  const BusConfig config = guarded(1);  // 20 ms
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  bus.configure();
  bus.activate();
  clock.set(500'000'000);  // the other buses took half a second
  test::PtyClient other(sim.endpoint());
  for (int id : {3, 4})
    EXPECT_EQ(reg8(other, static_cast<std::uint8_t>(id), xreg::bus_watchdog), 0u);
  bus.arm_device_guard();
  for (int id : {3, 4})
    EXPECT_EQ(reg8(other, static_cast<std::uint8_t>(id), xreg::bus_watchdog), 1u);
  std::vector<double> q(2, 0.0);
  bus.read(q);
  for (double& v : q) v += 0.05;
  bus.write(q);
  for (const DeviceStatus& d : bus.devices()) EXPECT_EQ(d.health, DeviceHealth::ok);
  clock.set(530'000'000);  // 30 ms without a word: now it fires
  EXPECT_EQ(reg8(other, 4, xreg::bus_watchdog), dxl::kBusWatchdogFired);
}

TEST(DynamixelBusOnSim, BusWatchdogIsJudgedOnTheClockOfTheRun) {
  // Lockstep: the simulated clock stands still while the machine is slow, so
  // real time that passes must not fire the watchdog; simulated time must.
  const BusConfig config = guarded(1);  // 20 ms
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  bus.configure();
  bus.activate();
  bus.arm_device_guard();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  test::PtyClient other(sim.endpoint());
  EXPECT_EQ(reg8(other, 3, xreg::bus_watchdog), 1u);
  clock.set(10'000'000);
  EXPECT_EQ(reg8(other, 3, xreg::bus_watchdog), 1u);  // fed 10 ms ago by that read
  clock.set(40'000'000);
  EXPECT_EQ(reg8(other, 3, xreg::bus_watchdog), dxl::kBusWatchdogFired);
  // Servo 4 heard nothing since activate (and the reads of 3 are not for it).
  EXPECT_EQ(reg8(other, 4, xreg::bus_watchdog), dxl::kBusWatchdogFired);
}

TEST(DynamixelBusOnSim, FiredBusWatchdogHoldsTheServoUntilTheNextConfigure) {
  const BusConfig config = guarded(3);
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  double stopped = 0.0;
  {
    // A run that dies mid-motion: goals sent, then silence (no deactivate).
    DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
    bus.configure();
    bus.activate();
    bus.arm_device_guard();
    std::vector<double> q(2, 0.0);
    bus.read(q);
    bus.write(std::vector<double>{1.0, -1.0});
    clock.set(30'000'000);
    bus.read(q);
    clock.set(200'000'000);
    stopped = sim.device_position(3);
    clock.set(400'000'000);
    EXPECT_NEAR(sim.device_position(3), stopped, 1e-6);
    EXPECT_LT(stopped, 0.9);  // stopped short of its goal
    // The dead host's goals no longer move it: refused, not taken.
    bus.read(q);
    bus.write(std::vector<double>{0.5, 0.5});
    bus.read(q);  // after the write, so it has been handled
    const auto log = sim.device_goal_log(3);
    ASSERT_FALSE(log.empty());
    EXPECT_FALSE(log.back().accepted);
    EXPECT_NEAR(sim.device_position(3), stopped, 1e-6);
  }
  test::PtyClient other(sim.endpoint());
  EXPECT_EQ(reg8(other, 3, xreg::bus_watchdog), dxl::kBusWatchdogFired);
  EXPECT_EQ(reg8(other, 3, xreg::moving), 0u);
  // The next run recovers it at configure, says so, and can move it again.
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  ASSERT_NO_THROW(bus.configure());
  EXPECT_NE(bus.watchdog_warning().find("Bus Watchdog had fired on id 3 (joint3), id 4 (joint4)"),
            std::string::npos)
      << bus.watchdog_warning();
  EXPECT_EQ(reg8(other, 3, xreg::bus_watchdog), 0u);
  ASSERT_NO_THROW(bus.activate());
  ASSERT_NO_THROW(bus.arm_device_guard());
  std::vector<double> q(2, 0.0);
  bus.read(q);
  bus.write(std::vector<double>{0.2, 0.0});
  bus.read(q);
  EXPECT_TRUE(sim.device_goal_log(3).back().accepted);
  clock.set(420'000'000);
  bus.read(q);
  EXPECT_GT(std::abs(sim.device_position(3) - stopped), 0.01);
  bus.deactivate();
}

TEST(DynamixelBusOnSim, AHostThatStallsRearmsTheBusWatchdogAndMovesOn) {
  // Real time on both sides: the host's bus thread stalls for longer than
  // the guard (the servos stop, as they must), then speaks again. The
  // guard is long enough that a loaded machine's pause between the calls
  // after the stall does not fire it a second time.
  const BusConfig config = guarded(15);  // 300 ms
  const MonotonicClock clock;
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
  bus.configure();
  bus.activate();
  bus.arm_device_guard();
  std::vector<double> q(2, 0.0);
  bus.read(q);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  {
    test::PtyClient other(sim.endpoint());
    EXPECT_EQ(reg8(other, 3, xreg::bus_watchdog), dxl::kBusWatchdogFired);
  }
  const double stopped = sim.device_position(3);
  bus.read(q);
  bus.write(std::vector<double>{stopped + 0.3, 0.0});
  bus.read(q);
  EXPECT_EQ(bus.watchdog_rearms(), 1u);
  EXPECT_TRUE(sim.device_goal_log(3).back().accepted);
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  bus.read(q);
  EXPECT_GT(sim.device_position(3), stopped + 0.01);
  bus.deactivate();
}

}  // namespace
}  // namespace animrt
