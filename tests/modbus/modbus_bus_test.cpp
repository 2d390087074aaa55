// The Modbus bus driver against the simulated drives (a real libmodbus
// server) over loopback TCP and over a pty in RTU, and the robot-file checks.

#include "animrt/bridge/modbus/modbus_bus.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <any>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/protocol.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/sim/dynamixel_servo.hpp"
#include "animrt/sim/modbus/modbus_sim_bus.hpp"
#include "support/eventually.hpp"

namespace animrt {
namespace {

const std::string kMaps = std::string(ANIMRT_SOURCE_DIR) + "/configs/modbus/";

// Two joints: a rotary drive on slave 1 and a linear actuator (on a 0.1 m
// lever) on slave 2.
std::string robot_text(const std::string& protocol, const std::string& extra_joint = "") {
  const std::string port = protocol == "modbus-tcp" ? "127.0.0.1:1502" : "/dev/null";
  // A 200 ms answer timeout needs a longer watchdog (every bus timeout is below it).
  return "name: drives\nloop: {rate_hz: 100}\nsafety: {watchdog_timeout_s: 0.5}\nbuses:\n"
         "  drives:\n    protocol: " +
         protocol + "\n    port: " + port + "\n    timeout_ms: 200\n" +
         // RTU: fast enough that two drives' traffic fits a 100 Hz cycle.
         (protocol == "modbus-rtu" ? "    baud: 230400\n" : "") +
         "joints:\n"
         "  pan:\n"
         "    limits: {min_deg: -90, max_deg: 90, velocity_dps: 100, acceleration_dps2: 500}\n"
         "    actuator: {bus: drives, slave: 1, map: " +
         kMaps +
         "position_drive.yaml}\n"
         "  lean:\n"
         "    limits: {min_deg: -20, max_deg: 20, velocity_dps: 20, acceleration_dps2: 100}\n"
         "    actuator: {bus: drives, slave: 2, map: " +
         kMaps + "linear_actuator.yaml, m_per_rad: 0.1, zero_m: 0.05}\n" + extra_joint +
         "motion: {type: gait, file: " + std::string(ANIMRT_SOURCE_DIR) +
         "/configs/gaits/walk.yaml}\n";
}

RobotConfig load(const std::string& text, const std::string& name = "robot.yaml") {
  // Per test (parameterised names contain '/'), so parallel tests never share a file.
  std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::replace(test.begin(), test.end(), '/', '_');
  const std::string path = ::testing::TempDir() + "/" + test + "_" + name;
  std::ofstream(path) << text;
  return load_robot_config(path);
}

std::string error_of(const std::string& text) {
  try {
    load(text, "bad.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// RTU with the host following the simulated drives' lockstep line, as a
// lockstep run does (simulated_backend.hpp).
const std::string kRtuLockstep = "modbus-rtu-lockstep";

struct Rig {
  ManualClock clock;
  RobotConfig config;
  std::unique_ptr<sim::ModbusSimBus> sim;
  std::unique_ptr<ModbusBus> bus;
  explicit Rig(const std::string& protocol, double reconnect_min_s = 0.01,
               int return_delay_us = 0) {
    const bool line = protocol == kRtuLockstep;
    config = load(robot_text(line ? "modbus-rtu" : protocol));
    BusConfig& b = config.buses[0];
    b.sim.return_delay_us = return_delay_us;
    sim = std::make_unique<sim::ModbusSimBus>(b, clock);
    sim->start();
    b.port = sim->endpoint();
    if (line) b.lockstep_line = sim->lockstep_line();
    auto* options = std::any_cast<ModbusBusOptions>(&b.options);
    options->reconnect_min_s = reconnect_min_s;
    options->reconnect_max_s = std::max(0.05, reconnect_min_s);
    bus = std::make_unique<ModbusBus>(b);
  }
  std::vector<double> step(const std::vector<double>& goal, int cycles = 1) {
    std::vector<double> pos(2, 0.0);
    for (int k = 0; k < cycles; ++k) {
      bus->write(goal);
      clock.advance(10'000'000);
      bus->read(pos);
    }
    return pos;
  }
};

class ModbusTransports : public ::testing::TestWithParam<std::string> {};

TEST_P(ModbusTransports, TracksGoalsWithOneRequestPerSlaveAndDirection) {
  Rig r(GetParam());
  r.bus->configure();
  std::vector<double> pos(2, 99.0);
  r.bus->read(pos);
  // The simulated drives start a few degrees off zero.
  EXPECT_NEAR(pos[0], sim::initial_offset_rad(1), 1e-4);
  EXPECT_NEAR(pos[1], sim::initial_offset_rad(2), 1e-3);
  r.bus->activate();
  const std::uint64_t before = r.bus->requests();
  const std::vector<double> goal{deg_to_rad(30), deg_to_rad(-10)};
  pos = r.step(goal, 100);  // 1 s
  // One read (each map keeps present and status in one table) and one write
  // per slave and cycle.
  EXPECT_EQ(r.bus->requests() - before, 100u * 2 * 2);
  EXPECT_NEAR(pos[0], goal[0], 1e-3);
  EXPECT_NEAR(pos[1], goal[1], 2e-4 / 0.1);  // 0.01 mm counts on a 0.1 m lever
  EXPECT_NEAR(r.sim->device_position(1), goal[0], 1e-3);
  for (const auto& d : r.bus->devices()) {
    EXPECT_EQ(d.health, DeviceHealth::ok);
    EXPECT_EQ(d.timeouts + d.exceptions + d.crc_errors + d.protocol_errors, 0u);
  }
  r.bus->deactivate();
  const double held = r.sim->device_position(1);
  r.step(std::vector<double>{0.0, 0.0}, 10);  // disabled: the drive ignores goals
  EXPECT_DOUBLE_EQ(r.sim->device_position(1), held);
}

TEST_P(ModbusTransports, ExceptionsTimeoutsAndFaultsAreCountedPerDevice) {
  Rig r(GetParam());
  // Without joint limits in the binding the bus would clamp the goal below.
  BusConfig unlimited = r.config.buses[0];
  unlimited.actuators[1].min_position = -HUGE_VAL;
  unlimited.actuators[1].max_position = HUGE_VAL;
  r.bus = std::make_unique<ModbusBus>(unlimited);
  r.bus->configure();
  r.bus->activate();
  // A goal past the actuator's stroke: the drive answers exception 3.
  r.step({0.0, deg_to_rad(60)});
  EXPECT_EQ(r.bus->devices()[1].exceptions, 1u);
  EXPECT_EQ(r.bus->devices()[1].last_error_byte, 3);
  EXPECT_EQ(r.bus->devices()[0].exceptions, 0u);
  // A silent slave times out; the other is unaffected.
  r.sim->set_device_responding(2, false);
  auto pos = r.step({0.0, 0.0});
  EXPECT_EQ(r.bus->devices()[1].health, DeviceHealth::timeout);
  EXPECT_GE(r.bus->devices()[1].timeouts, 1u);
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::ok);
  r.sim->set_device_responding(2, true);
  // Fault bits in the status register are a hardware error.
  r.sim->set_device_hardware_error(1, 0x04);
  r.step({0.0, 0.0});
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::hardware_error);
  EXPECT_EQ(r.bus->devices()[0].hardware_error_status, 0x04);
  EXPECT_EQ(r.bus->devices()[1].health, DeviceHealth::ok);
}

TEST_P(ModbusTransports, ADeadSlaveCostsOneRequestAndOneTimeoutPerCycle) {
  Rig r(GetParam());
  r.bus->configure();
  r.bus->activate();
  r.step({0.0, 0.0});
  r.sim->set_device_responding(2, false);
  r.step({0.0, 0.0});  // the first cycle still writes: the slave answered last time
  const std::uint64_t requests = r.bus->requests();
  const std::uint64_t timeouts = r.bus->devices()[1].timeouts;
  r.step({0.1, 0.0}, 5);
  // Per cycle: slave 1 read + write, slave 2 read only.
  EXPECT_EQ(r.bus->requests() - requests, 5u * 3);
  EXPECT_EQ(r.bus->devices()[1].timeouts - timeouts, 5u);
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::ok);
  // Back: its goals are written again.
  r.sim->set_device_responding(2, true);
  r.step({0.1, 0.0}, 2);
  EXPECT_EQ(r.bus->devices()[1].health, DeviceHealth::ok);
}

TEST_P(ModbusTransports, GoalsAreClampedIntoTheJointLimitsAndNaNHolds) {
  Rig r(GetParam());
  r.bus->configure();
  r.bus->activate();
  // pan is limited to +-90 degrees by the robot file.
  r.step({deg_to_rad(170), 0.0}, 150);
  EXPECT_NEAR(r.sim->device_position(1), deg_to_rad(90), 1e-3);
  r.step({std::nan(""), 0.0}, 20);
  EXPECT_NEAR(r.sim->device_position(1), deg_to_rad(90), 1e-3);
  EXPECT_EQ(r.bus->devices()[0].exceptions, 0u);
}

TEST_P(ModbusTransports, ADriveSwitchedOffForItsHealthHasItsEnableOff) {
  Rig r(GetParam());
  r.bus->configure();
  r.bus->activate();
  r.step({0.0, 0.0}, 20);
  r.bus->switch_off(1);
  EXPECT_TRUE(r.bus->devices()[1].faulted);
  // The enable goes off in the next read: the drive no longer follows a goal.
  r.step({0.0, deg_to_rad(10)});
  const double held = r.sim->device_position(2);
  EXPECT_NEAR(held, 0.0, 1e-3);
  r.step({0.0, deg_to_rad(10)}, 30);
  EXPECT_DOUBLE_EQ(r.sim->device_position(2), held);
  EXPECT_NEAR(r.sim->device_position(1), 0.0, 1e-3);  // the other drive carries on
}

// The drive's firmware trips by itself when its thermal model passes its
// trip temperature: fault code 0x4310 and the output off, latched through a
// cooling until the host resets it (enable off, then on) below the trip.
TEST(ModbusBus, ADriveTripsOnOvertemperatureUntilAFaultResetOnceCooled) {
  Rig r("modbus-tcp");
  std::any_cast<ModbusBusOptions&>(r.config.buses[0].options).health =
      ModbusBusOptions::Health::packed;
  r.bus = std::make_unique<ModbusBus>(r.config.buses[0]);
  ASSERT_DOUBLE_EQ(r.config.buses[0].sim.health.trip_c, 80.0);
  r.bus->configure();
  r.bus->activate();
  const double lean = r.sim->device_position(2);
  r.step({0.0, lean}, 5);
  const auto code = [&] { return r.bus->devices()[1].reading.error_bits; };
  EXPECT_EQ(code(), 0u);
  using Kind = SimHealthInjection::Kind;
  r.sim->inject_device_health(2, {2, 0.0, Kind::temperature, 79.0});
  r.step({0.0, lean}, 2);
  EXPECT_EQ(code(), 0u);  // below the trip
  r.sim->inject_device_health(2, {2, 0.0, Kind::temperature, 85.0});
  r.step({0.0, lean}, 2);
  EXPECT_EQ(code(), 0x4310u);
  EXPECT_EQ(r.bus->error_words(1, code()), "driver overtemperature");
  // Its output is off: a new goal does not move it; the other drive follows.
  const double held = r.sim->device_position(2);
  EXPECT_NEAR(held, lean, 1e-3);
  r.step({deg_to_rad(10), lean + deg_to_rad(10)}, 30);
  EXPECT_EQ(r.sim->device_position(2), held);
  EXPECT_NEAR(r.sim->device_position(1), deg_to_rad(10), 1e-3);
  // Cooled, but not reset: still tripped.
  r.sim->inject_device_health(2, {2, 0.0, Kind::temperature, 60.0});
  r.step({deg_to_rad(10), lean + deg_to_rad(10)}, 30);
  EXPECT_EQ(code(), 0x4310u);
  EXPECT_EQ(r.sim->device_position(2), held);
  // A reset while still hot (77 C: within 5 C of the trip) does not clear it.
  r.sim->inject_device_health(2, {2, 0.0, Kind::temperature, 77.0});
  r.bus->deactivate();
  r.bus->activate();
  r.step({deg_to_rad(10), lean + deg_to_rad(10)}, 30);
  EXPECT_EQ(code(), 0x4310u);
  EXPECT_EQ(r.sim->device_position(2), held);
  // Cooled and reset: it follows again.
  r.sim->inject_device_health(2, {2, 0.0, Kind::temperature, 60.0});
  r.bus->deactivate();
  r.bus->activate();
  r.step({deg_to_rad(10), lean + deg_to_rad(10)}, 30);
  EXPECT_EQ(code(), 0u);
  EXPECT_NEAR(r.sim->device_position(2), lean + deg_to_rad(10), 1e-3);
  r.bus->deactivate();
}

INSTANTIATE_TEST_SUITE_P(TcpAndRtu, ModbusTransports,
                         ::testing::Values("modbus-tcp", "modbus-rtu", kRtuLockstep),
                         [](const auto& p) {
                           return p.param == "modbus-tcp"   ? "tcp"
                                  : p.param == "modbus-rtu" ? "rtu"
                                                            : "rtu_lockstep";
                         });

// Following the lockstep line, an answer the drives give later on the wall
// clock than the bus timeout (their thread ran late) is still the answer.
TEST(ModbusBus, OnALockstepLineAnAnswerLaterThanTheTimeoutIsNoTimeout) {
  Rig r(kRtuLockstep, 0.01, 300'000);  // past the bus's 200 ms
  ASSERT_NE(r.config.buses[0].lockstep_line, nullptr);
  r.bus->configure();
  std::vector<double> pos(2, 99.0);
  r.bus->read(pos);
  EXPECT_NEAR(pos[0], sim::initial_offset_rad(1), 1e-4);
  EXPECT_NEAR(pos[1], sim::initial_offset_rad(2), 1e-3);
  EXPECT_EQ(r.bus->devices()[0].timeouts + r.bus->devices()[1].timeouts, 0u);
}

TEST(ModbusBus, OnARealRtuLineARetriedReadsLateAnswerIsNotTakenForAnother) {
  // Slave 1's first answer leaves 1.5 timeouts late: configure's read of it
  // times out, the repeat takes that answer, and the repeat's own answer
  // comes while the host asks slave 2, then activate writes slave 1. An
  // RTU answer names no register: taken for the next request's, it failed
  // request after request (activate: "cannot enable slave 1").
  Rig r("modbus-rtu");
  r.sim->set_device_answer_delay(1, 300'000'000, 1);
  ASSERT_NO_THROW(r.bus->configure());
  ASSERT_NO_THROW(r.bus->activate());
  const std::vector<double> goal{deg_to_rad(5), deg_to_rad(-2)};
  const std::vector<double> pos = r.step(goal, 50);
  EXPECT_NEAR(pos[0], goal[0], 1e-3);
  EXPECT_NEAR(pos[1], goal[1], 2e-4 / 0.1);
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::ok);
  EXPECT_EQ(r.bus->devices()[1].health, DeviceHealth::ok);
}

TEST(ModbusBus, IllegalAddressIsExceptionTwoAtBringUp) {
  // The runtime thinks slave 1 is a linear actuator; the drive has the rotary map.
  ManualClock clock;
  RobotConfig drive = load(robot_text("modbus-tcp"));
  sim::ModbusSimBus sim(drive.buses[0], clock);
  sim.start();
  std::string text = robot_text("modbus-tcp");
  text.replace(text.find("slave: 2"), 8, "slave: 3");
  text.replace(text.find("slave: 1"), 8, "slave: 2");
  RobotConfig wrong = load(text, "wrong.yaml");
  wrong.buses[0].port = sim.endpoint();
  ModbusBus bus(wrong.buses[0]);
  try {
    bus.configure();
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("slave 2 (pan): exception 2 (illegal data address)"), std::string::npos)
        << what;
    EXPECT_NE(what.find("slave 3 (lean): no answer"), std::string::npos) << what;
  }
}

TEST(ModbusBus, AClientHoldingHalfAHeaderStallsNoOtherClient) {
  Rig r("modbus-tcp");
  r.bus->configure();
  const auto colon = r.sim->endpoint().rfind(':');
  const int port = std::stoi(r.sim->endpoint().substr(colon + 1));
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::uint8_t half[3] = {0x00, 0x01, 0x00};  // transaction id and half the protocol id
  ASSERT_EQ(::send(fd, half, sizeof half, 0), 3);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::uint64_t timeouts = r.bus->devices()[0].timeouts + r.bus->devices()[1].timeouts;
  r.step({0.0, 0.0}, 5);
  EXPECT_EQ(r.bus->devices()[0].timeouts + r.bus->devices()[1].timeouts, timeouts);
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::ok);
  EXPECT_EQ(r.bus->devices()[1].health, DeviceHealth::ok);
  ::close(fd);
}

TEST(ModbusBus, RtuFrameCutOffBySilenceDoesNotSwallowTheNextRequest) {
  Rig r("modbus-rtu");
  r.bus->configure();
  // Another writer on the line sends the start of a Read Holding Registers
  // frame to slave 1 and falls silent.
  const int fd = ::open(r.sim->endpoint().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(fd, 0);
  const std::uint8_t cut[4] = {0x01, 0x03, 0x00, 0x10};
  const std::uint64_t dropped = r.sim->stats().dropped;
  ASSERT_EQ(::write(fd, cut, sizeof cut), 4);
  // Until the simulated slaves saw the silence after it (their thread may
  // not run for a while on a loaded machine).
  ASSERT_TRUE(test::eventually([&] { return r.sim->stats().dropped == dropped + 4; }));
  const std::uint64_t timeouts = r.bus->devices()[0].timeouts + r.bus->devices()[1].timeouts;
  r.step({0.0, 0.0}, 3);
  EXPECT_EQ(r.bus->devices()[0].timeouts + r.bus->devices()[1].timeouts, timeouts);
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::ok);
  EXPECT_EQ(r.sim->stats().dropped, dropped + 4);
  ::close(fd);
}

TEST(ModbusBus, ADroppedConnectionIsReopenedWithBackoff) {
  // A backoff far longer than the two reads below take, even on a loaded
  // machine, so the second read falls within it.
  Rig r("modbus-tcp", 0.5);
  r.bus->configure();
  r.bus->activate();
  EXPECT_EQ(r.bus->reconnects(), 1u);
  r.sim->drop_connections();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::vector<double> pos(2);
  r.bus->read(pos);  // the request meets a closed socket
  EXPECT_FALSE(r.bus->connected());
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::timeout);
  // Within the backoff nothing is attempted (the listening server sees no
  // new connection); every device counts a timeout.
  const std::uint64_t connections = r.sim->stats().connections;
  const std::uint64_t timeouts = r.bus->devices()[0].timeouts;
  r.bus->read(pos);
  EXPECT_FALSE(r.bus->connected());
  EXPECT_EQ(r.bus->reconnects(), 1u);
  EXPECT_EQ(r.sim->stats().connections, connections);
  EXPECT_EQ(r.bus->devices()[0].timeouts, timeouts + 1);
  EXPECT_EQ(r.bus->devices()[1].health, DeviceHealth::timeout);
  bool back = false;
  for (int i = 0; i < 400 && !back; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    r.bus->read(pos);
    back = r.bus->devices()[0].health == DeviceHealth::ok;
  }
  EXPECT_TRUE(back);
  EXPECT_EQ(r.bus->reconnects(), 2u);
  EXPECT_GE(r.sim->stats().connections, 2u);
}

// The drive's communication timeout: a register map that names it, the bus
// key that sets it, written when the bus arms its device guards.
struct GuardedRig {
  ManualClock clock;
  RobotConfig config;
  std::unique_ptr<sim::ModbusSimBus> sim;
  std::unique_ptr<ModbusBus> bus;
  explicit GuardedRig(const std::string& device_watchdog_ms) {
    std::ifstream in(kMaps + "position_drive.yaml");
    std::stringstream map;
    map << in.rdbuf() << "watchdog: {register: 40, unit_ms: 10}\n";
    const std::string map_path = ::testing::TempDir() + "/guarded_drive_" +
                                 ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                                 ".yaml";
    std::ofstream(map_path) << map.str();
    config = load(
        "name: guarded\nloop: {rate_hz: 100}\nsafety: {watchdog_timeout_s: 0.5}\nbuses:\n"
        "  drives: {protocol: modbus-tcp, port: 127.0.0.1:1502, timeout_ms: 200, "
        "device_watchdog_ms: " +
        device_watchdog_ms +
        "}\njoints:\n  pan:\n"
        "    limits: {min_deg: -90, max_deg: 90, velocity_dps: 100, acceleration_dps2: 500}\n"
        "    actuator: {bus: drives, slave: 1, map: " +
        map_path + "}\nmotion: {type: gait, file: " + std::string(ANIMRT_SOURCE_DIR) +
        "/configs/gaits/walk.yaml}\n");
    BusConfig& b = config.buses[0];
    sim = std::make_unique<sim::ModbusSimBus>(b, clock);
    sim->start();
    b.port = sim->endpoint();
    bus = std::make_unique<ModbusBus>(b);
  }
  void cycles(double goal, int n) {
    std::vector<double> pos(1, 0.0);
    for (int k = 0; k < n; ++k) {
      bus->write(std::vector<double>{goal});
      clock.advance(10'000'000);
      bus->read(pos);
    }
  }
};

TEST(ModbusBus, ADriveWhoseHostFallsSilentDisablesWithinItsCommunicationTimeout) {
  GuardedRig r("50");
  EXPECT_EQ(std::any_cast<const ModbusJointOptions&>(r.config.buses[0].actuators[0].options)
                .watchdog_counts,
            5);
  r.bus->configure();
  r.bus->activate();
  r.bus->arm_device_guard();
  const double start = r.sim->device_position(1);
  r.cycles(start, 10);
  // The host's last goal, 60 degrees away, then nothing (killed): the drive
  // runs towards it at its rate limit for the 50 ms timeout, then stops.
  const double goal = start + deg_to_rad(60);
  r.bus->write(std::vector<double>{goal});
  r.clock.advance(40'000'000);
  const double moving = r.sim->device_position(1);
  EXPECT_GT(moving - start, deg_to_rad(5));
  r.clock.advance(60'000'000);
  const double stopped = r.sim->device_position(1);
  r.clock.advance(2'000'000'000);
  EXPECT_DOUBLE_EQ(r.sim->device_position(1), stopped);
  EXPECT_GT(goal - stopped, deg_to_rad(30));
  // Requests again: the output stays off until the host enables it.
  r.cycles(goal, 20);
  EXPECT_DOUBLE_EQ(r.sim->device_position(1), stopped);
  r.bus->deactivate();

  // The same drive with the guard off follows the last goal to the end.
  GuardedRig off("off");
  off.bus->configure();
  off.bus->activate();
  off.bus->arm_device_guard();
  const double from = off.sim->device_position(1);
  off.cycles(from, 10);
  off.bus->write(std::vector<double>{from + deg_to_rad(60)});
  off.clock.advance(2'000'000'000);
  EXPECT_NEAR(off.sim->device_position(1), from + deg_to_rad(60), 1e-3);
  off.bus->deactivate();
}

TEST(ModbusConfig, AWatchdogRegisterTakesTheBusKeyAndValidateSaysWhoHasNone) {
  GuardedRig r("50");
  const Protocol* protocol = find_protocol("modbus-tcp");
  ASSERT_NE(protocol, nullptr);
  EXPECT_EQ(protocol->device_guard_note(r.config.buses[0]), "");
  EXPECT_EQ(protocol->device_guard_note(load(robot_text("modbus-tcp")).buses[0]),
            "no device-side guard (a register map names no watchdog register; set the drive's "
            "own communication timeout with its vendor tool): if the host dies, the drives hold "
            "their last target");
  GuardedRig off("off");
  EXPECT_EQ(protocol->device_guard_note(off.config.buses[0]),
            "no device-side guard (device_watchdog_ms: off): if the host dies, the drives hold "
            "their last target");
}

TEST(ModbusConfig, ErrorsNameFileLineAndKey) {
  EXPECT_EQ(load(robot_text("modbus-tcp")).buses[0].actuators[1].device_id, 2);
  std::string text = robot_text("modbus-tcp");
  text.replace(text.find("m_per_rad: 0.1"), 14, "m_per_rad: 0.5");
  const std::string range = error_of(text);
  EXPECT_NE(range.find("bad.yaml:14:"), std::string::npos) << range;
  EXPECT_NE(range.find("joints.lean.limits.min_deg: -20 deg maps to -0.124533"), std::string::npos)
      << range;
  EXPECT_NE(range.find("outside the range of"), std::string::npos) << range;

  text = robot_text("modbus-tcp");
  text.replace(text.find(", m_per_rad: 0.1, zero_m: 0.05"), 30, "");
  EXPECT_NE(error_of(text).find("joints.lean.actuator: missing key m_per_rad"), std::string::npos)
      << error_of(text);

  const std::string twice = error_of(robot_text(
      "modbus-tcp",
      "  tilt:\n    limits: {min_deg: -9, max_deg: 9, velocity_dps: 9, acceleration_dps2: 9}\n"
      "    actuator: {bus: drives, slave: 1, map: " +
          kMaps + "position_drive.yaml}\n"));
  EXPECT_NE(
      twice.find(
          "joints.tilt.actuator.slave: registers overlap: joint tilt and joint pan on slave 1"),
      std::string::npos)
      << twice;

  // Health read from a map that names no health registers (position_drive.yaml).
  text = robot_text("modbus-tcp");
  text.replace(text.find("timeout_ms: 200"), 15, "timeout_ms: 200\n    health: packed");
  const std::string no_health = error_of(text);
  EXPECT_NE(no_health.find("bad.yaml:13:"), std::string::npos) << no_health;
  EXPECT_NE(no_health.find("joints.pan.actuator.map: bus drives reads health, but the register "
                           "map"),
            std::string::npos)
      << no_health;
  text.replace(text.find("health: packed"), 14, "health: always");
  EXPECT_NE(error_of(text).find(
                "buses.drives.health: expected off, packed or round_robin, found \"always\""),
            std::string::npos)
      << error_of(text);

  text = robot_text("modbus-tcp");
  text.replace(text.find("port: 127.0.0.1:1502"), 20, "port: localhost");
  EXPECT_NE(error_of(text).find("buses.drives.port: expected HOST:PORT"), std::string::npos);
}

}  // namespace
}  // namespace animrt
