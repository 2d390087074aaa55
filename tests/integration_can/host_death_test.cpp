// The host dies mid-motion and the CAN devices of
// configs/robots/quadruped_can.yaml stop by themselves: the CiA 402 drive
// leaves Operation Enabled (heartbeat consumer, 6007h) and every MIT motor
// goes limp (CAN timeout) within device_watchdog_ms of the last frame the
// host sent.
//
// A kill -9 cannot be staged across processes here: the in-process virtual
// CAN bus is the only CAN this kernel has (`animrt sim` serves SocketCAN
// interfaces, which it cannot open). So the host side is the runtime's own
// buses, driven cycle by cycle on a lockstep clock as the loop drives them,
// and its death is what a kill leaves: mid-cycle, no deactivate, no further
// frame, while the clock goes on. The drive is then read from the wire by a
// client written here (SDO upload of the statusword, EMCY), the motors from
// the simulation's side.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/figure_backend.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace animrt::host_death_test {
namespace {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";
constexpr Nanos kMs = 1'000'000;
constexpr canid_t kDrive = 32;
constexpr int kLeft[] = {1, 2, 3, 4, 5, 6};
constexpr int kRight[] = {7, 8, 9, 11, 12};

// A CANopen client of its own: SDO upload of one object, EMCY and the
// host's heartbeat seen on the way.
class Client {
 public:
  explicit Client(const std::string& interface)
      : transport_(VirtualCanBus::named(interface)->attach()) {
    const can_filter filters[] = {
        {0x580 + kDrive, CAN_SFF_MASK}, {0x080 + kDrive, CAN_SFF_MASK}, {0x77F, CAN_SFF_MASK}};
    transport_->set_filters(filters);
  }
  // Frames already on the bus, without waiting.
  void take_pending() {
    can_frame f;
    while (transport_->receive(f, std::chrono::microseconds(0))) note(f);
  }
  // Expedited SDO upload (command 0x40) of index:sub from the drive.
  std::uint32_t upload(std::uint16_t index, std::uint8_t sub) {
    take_pending();  // the runtime's own SDO answers, from its bring-up
    can_frame request{};
    request.can_id = 0x600 + kDrive;
    request.len = 8;
    request.data[0] = 0x40;
    request.data[1] = static_cast<std::uint8_t>(index);
    request.data[2] = static_cast<std::uint8_t>(index >> 8);
    request.data[3] = sub;
    transport_->send(request);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    can_frame f;
    while (std::chrono::steady_clock::now() < deadline) {
      if (!transport_->receive(f, std::chrono::milliseconds(100))) continue;
      note(f);
      if (f.can_id == 0x580 + kDrive && (f.data[0] & 0xE0) == 0x40 &&
          f.data[1] == request.data[1] && f.data[2] == request.data[2] && f.data[3] == sub) {
        return static_cast<std::uint32_t>(f.data[4] | (f.data[5] << 8) | (f.data[6] << 16) |
                                          (f.data[7] << 24));
      }
    }
    ADD_FAILURE() << "no SDO answer from node " << kDrive;
    return 0;
  }
  // Statusword bits 0-3, 5, 6 of Operation Enabled: 0x27 under mask 0x6F.
  bool operation_enabled() { return (upload(0x6041, 0) & 0x6F) == 0x27; }

  std::vector<std::uint16_t> emcy_codes;
  bool heartbeat_seen = false;

 private:
  void note(const can_frame& f) {
    if (f.can_id == 0x080 + kDrive && f.len == 8) {
      emcy_codes.push_back(static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8)));
    }
    if (f.can_id == 0x77F && f.len == 1 && f.data[0] == 0x05) heartbeat_seen = true;
  }
  std::unique_ptr<CanFrameTransport> transport_;
};

// The quadruped's three CAN buses and their simulated devices, built by the
// figure builder on its lockstep clock as `animrt run --lockstep` builds
// them; the host side is the figure's buses, which a test drives itself (the
// loop never runs).
struct Rig {
  SimulatedBackend simulated;
  std::unique_ptr<Figure> figure;  // closes its buses before the devices stop
  ManualClock* clock = nullptr;

  explicit Rig(int watchdog_override_ms = -1) {
    FigureOptions options;
    options.lockstep = true;  // timeouts widen as in `animrt run --lockstep`
    options.edit = [watchdog_override_ms](RobotConfig& config) {
      if (watchdog_override_ms < 0) return;
      auto mit = std::any_cast<MitBusOptions>(config.buses[0].options);
      mit.device_watchdog_ms = watchdog_override_ms;
      config.buses[0].options = mit;
      config.buses[1].options = mit;
      auto drive = std::any_cast<Cia402BusOptions>(config.buses[2].options);
      drive.device_watchdog_ms = watchdog_override_ms;
      config.buses[2].options = drive;
    };
    figure = std::make_unique<Figure>(load_robot(kRobot), simulated, options);
    clock = figure->run_options().lockstep_clock;  // a run would advance it; a test does
    clock->set(1000 * kMs);
  }
  sim::CanSimBus& can(std::size_t i) {
    return dynamic_cast<sim::CanSimBus&>(*simulated.devices()[i]);
  }
  int watchdog_ms() const {
    return std::any_cast<Cia402BusOptions>(figure->config().buses[2].options).device_watchdog_ms;
  }
  bool any_motor_limp() {
    for (int id : kLeft)
      if (can(0).device_guard_fired(id)) return true;
    for (int id : kRight)
      if (can(1).device_guard_fired(id)) return true;
    return false;
  }
  bool every_motor_limp() {
    for (int id : kLeft)
      if (!can(0).device_guard_fired(id)) return false;
    for (int id : kRight)
      if (!can(1).device_guard_fired(id)) return false;
    return true;
  }
};

// The runtime's side: a figure's buses, brought up and cycled as the loop
// does (read every bus, then write every bus).
struct Host {
  std::vector<ActuatorBus*> buses;
  std::vector<std::vector<double>> start, q;

  explicit Host(Figure& figure) {
    for (std::size_t b = 0; b < figure.bus_count(); ++b) buses.push_back(&figure.bus(b));
    for (auto* bus : buses) {
      bus->configure();
      start.emplace_back(bus->config().actuators.size(), 0.0);
      bus->read(start.back());
    }
    q = start;
    for (auto* bus : buses) bus->activate();
    for (auto* bus : buses) bus->arm_device_guard();
  }
  // One cycle at `t`: a slow sway around the measured pose (0.2 rad, 1 Hz).
  void cycle(Rig& rig, Nanos t) {
    rig.clock->set(t);
    for (std::size_t b = 0; b < buses.size(); ++b) buses[b]->read(q[b]);
    const double s = 0.2 * std::sin(2.0 * 3.141592653589793 * static_cast<double>(t) * 1e-9);
    for (std::size_t b = 0; b < buses.size(); ++b) {
      for (std::size_t d = 0; d < q[b].size(); ++d) q[b][d] = start[b][d] + s;
      buses[b]->write(q[b]);
    }
  }
};

// Long enough for the simulations' threads (which poll every 2 ms) to act
// on a new clock value.
void let_the_devices_poll() { std::this_thread::sleep_for(std::chrono::milliseconds(30)); }

TEST(HostDeath, EveryDeviceStopsWithinTheWatchdogTime) {
  Rig rig;
  const Nanos watchdog = static_cast<Nanos>(rig.watchdog_ms()) * kMs;
  ASSERT_EQ(rig.watchdog_ms(), 50);  // the default at 200 Hz
  Client client("can1");
  Host host(*rig.figure);

  // A second of motion; the last host heartbeat and the last cycle noted.
  Nanos t = 1000 * kMs, last_heartbeat = -1;
  for (int k = 1; k <= 200; ++k) {
    t += 5 * kMs;
    host.cycle(rig, t);
    client.heartbeat_seen = false;
    client.take_pending();
    if (client.heartbeat_seen) last_heartbeat = t;
  }
  const Nanos death = t;
  ASSERT_GE(last_heartbeat, death - 15 * kMs);
  ASSERT_TRUE(client.operation_enabled());
  ASSERT_FALSE(rig.any_motor_limp());
  // Death: the host's buses stay, silent; nothing is sent from here on.

  // Time goes on, a millisecond at a time. The drive: in Operation Enabled
  // up to the consumer time after the last heartbeat, out of it one
  // millisecond later, so within the watchdog time of the host's death. The
  // motors: driven at `death` for the last time, not limp at the timeout.
  Nanos left_at = -1;
  for (Nanos now = death + kMs; now <= death + watchdog; now += kMs) {
    rig.clock->set(now);
    if (left_at < 0 && !client.operation_enabled()) left_at = now;
  }
  let_the_devices_poll();
  EXPECT_FALSE(rig.any_motor_limp());
  rig.clock->set(death + watchdog + kMs);
  if (left_at < 0 && !client.operation_enabled()) left_at = death + watchdog + kMs;
  ASSERT_GT(left_at, 0) << "the drive stayed in Operation Enabled";
  EXPECT_EQ(left_at, last_heartbeat + watchdog + kMs);
  EXPECT_LE(left_at - death, watchdog + kMs);
  ASSERT_FALSE(client.emcy_codes.empty());
  EXPECT_EQ(client.emcy_codes.back(), 0x8130);  // heartbeat error
  EXPECT_EQ(client.upload(0x1001, 0), 0x11u);   // generic + communication
  // Quick stop (6007h = 3), and the drive's 605Ah keeps it there.
  EXPECT_EQ(client.upload(0x6041, 0) & 0x6F, 0x07u);
  // ... and every motor limp a millisecond after its timeout.
  for (int i = 0; i < 100 && !rig.every_motor_limp(); ++i) let_the_devices_poll();
  EXPECT_TRUE(rig.every_motor_limp());
  // Limp: nothing drives them toward their last goals any more.
  const double held = rig.simulated.devices()[0]->device_position(1);
  rig.clock->set(death + 2000 * kMs);
  EXPECT_NEAR(rig.simulated.devices()[0]->device_position(1), held, 1e-9);

  // A new host brings the figure up again: the drive is taken out of its
  // quick stop, the motors into motor mode; a clean end clears the guard.
  // It is a figure of its own, built on the devices as a second process
  // would find them: as hardware, at the interfaces the first figure opened.
  LoadedRobot robot = load_robot(kRobot);
  robot.config = rig.figure->config();
  HardwareBackend devices;
  Figure second(std::move(robot), devices);
  Host again(second);
  again.cycle(rig, death + 2005 * kMs);
  EXPECT_TRUE(client.operation_enabled());
  EXPECT_EQ(client.upload(0x1001, 0), 0u);
  EXPECT_FALSE(rig.any_motor_limp());
  EXPECT_EQ(client.upload(0x1016, 1), 0x007F0032u);
  for (auto* bus : again.buses) bus->deactivate();
  EXPECT_EQ(client.upload(0x1016, 1), 0u);
  EXPECT_FALSE(client.operation_enabled());
}

TEST(HostDeath, WithTheGuardOffTheDevicesKeepGoing) {
  Rig rig(0);
  Client client("can1");
  Host host(*rig.figure);
  Nanos t = 1000 * kMs;
  for (int k = 1; k <= 100; ++k) host.cycle(rig, t += 5 * kMs);
  rig.clock->set(t + 1000 * kMs);
  let_the_devices_poll();
  EXPECT_TRUE(client.operation_enabled());
  EXPECT_FALSE(rig.any_motor_limp());
  EXPECT_EQ(client.upload(0x1016, 1), 0u);
  for (auto* bus : host.buses) bus->deactivate();
}

// The buses come up one after another; the devices' guards start only once
// all are up, so a slow bus (here 40 ms, within the motors' 50 ms) does not
// make the others' motors go limp. One that ran out meanwhile (80 ms) is
// not held again at its old pose (it may have sagged): the run is refused.
TEST(HostDeath, ASlowBusComingUpDoesNotCountAgainstTheOthers) {
  for (const Nanos bring_up : {40 * kMs, 80 * kMs}) {
    Rig rig;
    std::vector<ActuatorBus*> buses;
    for (std::size_t b = 0; b < rig.figure->bus_count(); ++b) buses.push_back(&rig.figure->bus(b));
    for (auto* bus : buses) bus->configure();
    buses[0]->activate();
    buses[1]->activate();
    rig.clock->set(rig.clock->now() + bring_up);
    buses[2]->activate();
    std::string refused;
    try {
      for (auto* bus : buses) bus->arm_device_guard();
    } catch (const DeviceError& e) {
      refused = e.what();
    }
    let_the_devices_poll();
    if (bring_up < 50 * kMs) {
      EXPECT_EQ(refused, "");
      // 30 ms after arming, 70 ms after the motors were activated: arming
      // held them again, so they are still driven.
      rig.clock->set(rig.clock->now() + 30 * kMs);
      let_the_devices_poll();
      EXPECT_FALSE(rig.any_motor_limp());
    } else {
      EXPECT_NE(refused.find("the motors' CAN timeout (50 ms) ran out while the other buses "
                             "came up (80 ms)"),
                std::string::npos)
          << refused;
    }
    for (auto* bus : buses) bus->deactivate();
  }
}

}  // namespace
}  // namespace animrt::host_death_test
