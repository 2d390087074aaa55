// Homing a CiA 402 drive on its current position through Cia402Bus::set_home
// (what calibrate does for a CAN joint), against the simulated drive on the
// in-process virtual bus: homing mode and method 37 are written, a rising
// controlword bit 4 starts it, the position actual then reads the home
// offset without the drive moving, the drive ends disabled and back in
// cyclic synchronous position mode, and the home survives a reset of the
// node and plays as the run's zero. While the figure is limp (disabled,
// pre-operational) the bus still reads the position, as calibrate follows
// a joint moved by hand.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"

namespace animrt::cia402_homing_test {
namespace {

constexpr Nanos kMs = 1'000'000;
constexpr canid_t kNode = 21;
constexpr std::int32_t kHome = 123'456;

struct Rig {
  ManualClock clock;
  BusConfig config;
  std::unique_ptr<sim::CanSimBus> sim;
  std::unique_ptr<CanFrameTransport> sniffer;
  std::unique_ptr<Cia402Bus> bus;

  explicit Rig(const std::string& name) {
    clock.set(1000 * kMs);
    config.name = "wrist";
    config.protocol = "cia402";
    config.port = "virtual:" + name;
    config.timeout_s = 0.5;  // a loaded machine must not time out
    config.options = Cia402BusOptions{};
    ActuatorBinding b;
    b.joint = "wrist";
    b.joint_index = 0;
    b.device_id = kNode;
    b.ticks_per_rad = 65536 / 6.283185307179586;
    b.zero_ticks = kHome;  // the robot file's zero: where homing puts the home
    // The drive powers up reading near 0 counts, wherever the joint is.
    BusConfig drive_side = config;
    drive_side.actuators.push_back(b);
    drive_side.actuators[0].zero_ticks = 0;
    config.actuators.push_back(b);
    sim = std::make_unique<sim::CanSimBus>(drive_side, clock, sim::CanSimAttach::in_process);
    sim->start();
    sniffer = VirtualCanBus::named(name)->attach();
    bus = std::make_unique<Cia402Bus>(config, open_can(config.port));
  }
  ~Rig() {
    bus.reset();
    sim->stop();
  }
  std::vector<can_frame> drain() {
    std::vector<can_frame> frames;
    can_frame f;
    while (sniffer->receive(f, std::chrono::milliseconds(20))) frames.push_back(f);
    return frames;
  }
  std::int32_t position() {
    return static_cast<std::int32_t>(bus->sdo_read(0, cia402::obj::position_actual, 0));
  }
};

bool is_download(const can_frame& f, std::uint16_t index, std::uint32_t value) {
  return f.can_id == canopen::kRsdoBase + kNode && f.len == 8 && (f.data[0] & 0xE0) == 0x20 &&
         canopen::get_le(f.data + 1, 2) == index &&
         (canopen::get_le(f.data + 4, 4) & 0xFF) == (value & 0xFF);
}

TEST(Cia402Homing, HomesOnTheCurrentPositionWithoutMoving) {
  Rig rig("homing_here");
  rig.bus->configure();
  rig.bus->deactivate();  // limp, as calibrate holds a figure
  rig.drain();
  const std::int32_t before = rig.position();
  ASSERT_GT(std::abs(before - kHome), 1000);  // the home is somewhere else until homed
  // Limp, its position is still read (by SDO: no PDOs while disabled).
  std::vector<double> limp(1, 99.0);
  rig.bus->read(limp);  // configure's reading
  rig.bus->read(limp);
  EXPECT_NEAR(limp[0], rig.config.actuators[0].to_rad(before), 1e-6);

  EXPECT_EQ(rig.bus->set_home(0, kHome), kHome);
  const std::vector<can_frame> frames = rig.drain();
  // Homing mode (6060h = 6) and method 37 (6098h) by SDO, then the start:
  // an RPDO whose controlword has bit 4 set after one with it clear.
  bool mode6 = false, method37 = false, started = false;
  std::uint16_t previous = 0;
  for (const can_frame& f : frames) {
    mode6 = mode6 || is_download(f, cia402::obj::modes_of_operation, 6);
    method37 = method37 || is_download(f, cia402::obj::homing_method, 37);
    if (f.can_id == canopen::kRpdo1Base + kNode && f.len >= 2) {
      const auto cw = static_cast<std::uint16_t>(canopen::get_le(f.data, 2));
      if ((cw & 0x10) && !(previous & 0x10) && (cw & 0x0F) == 0x0F) started = true;
      previous = cw;
    }
  }
  EXPECT_TRUE(mode6);
  EXPECT_TRUE(method37);
  EXPECT_TRUE(started);

  // It reads the home where it rests, and stays there (nothing moved it).
  EXPECT_EQ(rig.position(), kHome);
  rig.clock.set(3000 * kMs);
  EXPECT_EQ(rig.position(), kHome);
  rig.bus->read(limp);  // the home is the joint's zero
  EXPECT_NEAR(limp[0], 0.0, 1e-6);
  EXPECT_EQ(rig.bus->devices()[0].health, DeviceHealth::ok);
  // Disabled and back in cyclic synchronous position mode.
  EXPECT_EQ(rig.bus->sdo_read(0, cia402::obj::modes_of_operation, 0),
            static_cast<std::uint32_t>(cia402::kModeCsp));
  const auto sw = static_cast<std::uint16_t>(rig.bus->sdo_read(0, cia402::obj::statusword, 0));
  EXPECT_EQ(cia402::decode_statusword(sw), cia402::State::switch_on_disabled);

  // The drive keeps its home across a reset of the node.
  rig.bus->nmt(canopen::NmtCommand::reset_node, 0);
  rig.drain();
  EXPECT_EQ(rig.position(), kHome);

  // A run on it: the home is the joint's zero.
  rig.bus->configure();
  rig.bus->activate();
  std::vector<double> q(1, 1.0);
  rig.clock.set(3010 * kMs);
  rig.bus->read(q);
  EXPECT_NEAR(q[0], 0.0, 1e-4);
  rig.bus->write(q);
  rig.bus->deactivate();
}

TEST(Cia402Homing, RefusedWhileTheBusRuns) {
  Rig rig("homing_running");
  rig.bus->configure();
  rig.bus->activate();
  EXPECT_THROW(rig.bus->set_home(0, kHome), DeviceError);
  rig.bus->deactivate();
}

}  // namespace
}  // namespace animrt::cia402_homing_test
