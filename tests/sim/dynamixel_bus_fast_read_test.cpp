// The runtime's DynamixelBus reading through Fast Sync Read from the
// simulated servos: when it is chosen, what a silent servo in the middle
// costs, and the per-answer timeout.

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/dynamixel_sim_bus.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

BusConfig bus_of(int servos, int firmware, dxl::FastRead mode, double timeout_s = 0.1) {
  BusConfig config;
  config.name = "legs";
  config.protocol = "dynamixel2";
  config.timeout_s = timeout_s;
  config.sim.firmware_version = firmware;
  dxl::BusOptions options;
  options.fast_read = mode;
  config.options = options;
  for (int id = 1; id <= servos; ++id) {
    ActuatorBinding b;
    b.joint = "joint" + std::to_string(id);
    b.joint_index = id - 1;
    b.device_id = id;
    dxl::DeviceOptions o;
    o.model_number = dxl::find_x_model("XM430-W350")->number;
    b.options = o;
    config.actuators.push_back(b);
  }
  return config;
}

struct Rig {
  explicit Rig(const BusConfig& c) : config(c), sim(config, clock) {
    sim.start();
    bus = std::make_unique<DynamixelBus>(config, open_serial(sim.endpoint(), 1'000'000));
  }
  BusConfig config;
  ManualClock clock{0};
  sim::DynamixelSimBus sim;
  std::unique_ptr<DynamixelBus> bus;
};

TEST(DynamixelBusFastRead, AutoChoosesFastReadWhenEveryServoSupportsIt) {
  Rig rig(bus_of(3, 46, dxl::FastRead::automatic));
  rig.bus->configure();
  EXPECT_TRUE(rig.bus->fast_read_active());
  EXPECT_EQ(rig.bus->model_number(0), 1020);
  EXPECT_EQ(rig.bus->firmware_version(0), 46);
  std::vector<double> q(3, 99.0);
  rig.bus->read(q);  // hands out configure()'s values, then reads
  rig.bus->read(q);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(q[static_cast<std::size_t>(i)], rig.sim.device_position(i + 1), 1e-3) << i;
    const DeviceStatus& st = rig.bus->devices()[static_cast<std::size_t>(i)];
    EXPECT_EQ(st.health, DeviceHealth::ok);
    EXPECT_EQ(st.timeouts + st.crc_errors + st.protocol_errors, 0u);
  }
}

TEST(DynamixelBusFastRead, AutoKeepsSyncReadForOldFirmwareAndOffAlways) {
  Rig old(bus_of(2, 44, dxl::FastRead::automatic));
  old.bus->configure();
  EXPECT_FALSE(old.bus->fast_read_active());
  Rig off(bus_of(2, 46, dxl::FastRead::off));
  off.bus->configure();
  EXPECT_FALSE(off.bus->fast_read_active());
  Rig on(bus_of(2, 46, dxl::FastRead::on));
  on.bus->configure();
  EXPECT_TRUE(on.bus->fast_read_active());
}

TEST(DynamixelBusFastRead, ForcedOnOldFirmwareTimesOutEveryServo) {
  // `on` is obeyed even when the servos cannot: every read then times out.
  Rig rig(bus_of(2, 38, dxl::FastRead::on, 0.05));
  rig.bus->configure();
  ASSERT_TRUE(rig.bus->fast_read_active());
  std::vector<double> q(2, 0.0);
  rig.bus->read(q);
  for (const DeviceStatus& st : rig.bus->devices()) {
    EXPECT_EQ(st.timeouts, 1u);
    EXPECT_EQ(st.health, DeviceHealth::timeout);
  }
}

TEST(DynamixelBusFastRead, ConfiguredModelMustMatchTheServo) {
  BusConfig config = bus_of(2, 46, dxl::FastRead::automatic);
  dxl::DeviceOptions other;
  other.model_number = dxl::find_x_model("XH540-W270")->number;
  Rig rig(config);
  // The bus expects an XH540 at id 2; the simulated servo is an XM430.
  BusConfig expect = config;
  expect.actuators[1].options = other;
  DynamixelBus bus(expect, open_serial(rig.sim.endpoint(), 1'000'000));
  try {
    bus.configure();
    FAIL() << "configure() accepted the wrong model";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("id 2 (joint2) is a XM430-W350 (model number 1020), the "
                                         "config says XH540-W270 (model number 1100)"),
              std::string::npos)
        << e.what();
  }
}

TEST(DynamixelBusFastRead, SilentServoInTheMiddleCostsOnlyItself) {
  Rig rig(bus_of(4, 46, dxl::FastRead::automatic, 0.1));
  rig.bus->configure();
  ASSERT_TRUE(rig.bus->fast_read_active());
  std::vector<double> q(4, 0.0);
  rig.bus->read(q);  // configure()'s values
  // Move every servo so a stale value cannot pass for a fresh one.
  rig.bus->activate();
  rig.bus->write(std::vector<double>{0.5, 0.5, 0.5, 0.5});
  rig.bus->read(q);  // the goal takes effect (lockstep: with the next answered packet)
  rig.sim.set_device_responding(2, false);
  rig.clock.set(5'000'000'000);
  std::fill(q.begin(), q.end(), 99.0);
  rig.bus->read(q);
  const auto dev = rig.bus->devices();
  for (int id : {1, 3, 4}) {
    const std::size_t i = static_cast<std::size_t>(id - 1);
    EXPECT_NEAR(q[i], rig.sim.device_position(id), 1e-3) << id;
    EXPECT_NEAR(q[i], 0.5, 1e-2) << id;
    EXPECT_EQ(dev[i].timeouts, 0u) << id;
    EXPECT_EQ(dev[i].health, DeviceHealth::ok) << id;
  }
  EXPECT_EQ(dev[1].timeouts, 1u);
  EXPECT_EQ(dev[1].health, DeviceHealth::timeout);
  EXPECT_EQ(q[1], 99.0);  // nothing read, nothing written
  // Back: the next read has all four.
  rig.sim.set_device_responding(2, true);
  rig.bus->read(q);
  EXPECT_EQ(dev[1].health, DeviceHealth::ok);
  EXPECT_NEAR(q[1], rig.sim.device_position(2), 1e-3);
}

TEST(DynamixelBusFastRead, CycleNeverAllocates) {
  Rig rig(bus_of(4, 46, dxl::FastRead::automatic, 0.05));
  rig.bus->configure();
  ASSERT_TRUE(rig.bus->fast_read_active());
  rig.bus->activate();
  std::vector<double> q(4, 0.0);
  rig.bus->read(q);
  rig.bus->write(q);
  long allocations = 0;
  const auto cycle = [&] {
    test::AllocationCounter counter;  // this thread only: the simulator is not counted
    rig.bus->read(q);
    rig.bus->write(q);
    allocations += counter.count();
  };
  cycle();
  rig.sim.set_device_responding(3, false);  // the slice-by-slice path with a gap
  cycle();
  rig.sim.set_device_responding(3, true);
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(rig.bus->devices()[2].timeouts, 1u);
  EXPECT_EQ(rig.bus->devices()[3].timeouts, 0u);
}

// 12 servos, each answer 50 ms after the one before, timeout 400 ms: the
// twelve answers of a Sync Read (or slices of a Fast Sync Read) take 600 ms,
// more than one timeout; since the timeout is per answer, neither times out
// (with one deadline for the whole read, the last four would). Each answer
// has 350 ms to spare for a machine too loaded to run the simulator.
void twelve_late_answers(dxl::FastRead mode) {
  Rig rig(bus_of(12, 46, mode, 0.4));
  rig.bus->configure();
  EXPECT_EQ(rig.bus->fast_read_active(), mode == dxl::FastRead::on);
  for (int id = 1; id <= 12; ++id) rig.sim.set_device_answer_delay(id, 50'000'000);
  std::vector<double> q(12, 0.0);
  rig.bus->read(q);
  for (const DeviceStatus& st : rig.bus->devices()) {
    EXPECT_EQ(st.timeouts, 0u) << st.device_id;
    EXPECT_EQ(st.protocol_errors, 0u) << st.device_id;
    EXPECT_EQ(st.health, DeviceHealth::ok) << st.device_id;
  }
  for (int id = 1; id <= 12; ++id) {
    EXPECT_NEAR(q[static_cast<std::size_t>(id - 1)], rig.sim.device_position(id), 1e-3) << id;
  }
}

TEST(DynamixelBusFastRead, TwelveSlowAnswersDoNotTimeOutASyncRead) {
  twelve_late_answers(dxl::FastRead::off);
}

TEST(DynamixelBusFastRead, TwelveSlowSlicesDoNotTimeOutAFastSyncRead) {
  twelve_late_answers(dxl::FastRead::on);
}

}  // namespace
}  // namespace animrt
