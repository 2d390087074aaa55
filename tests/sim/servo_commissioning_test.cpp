// Simulated serial servos as a user commissions them: EEPROM that survives a
// Reboot, a power cycle and (with a state file) a restart of the simulator,
// RAM that does not; Factory Reset with its three options; servos that start
// at factory settings with one plugged in; Feetech EEPROM kept only while
// its lock is open.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "animrt/sim/dynamixel_sim_bus.hpp"
#include "animrt/sim/feetech/feetech_sim_bus.hpp"
#include "animrt/sim/servo_state_file.hpp"
#include "sim/pty_client.hpp"

namespace animrt {
namespace {

namespace xreg = dxl::xreg;
using test::Bytes;

BusConfig dynamixel_bus(std::vector<int> ids) {
  BusConfig config;
  config.name = "legs";
  config.protocol = "dynamixel2";
  for (int id : ids) {
    ActuatorBinding b;
    b.joint = "joint" + std::to_string(id);
    b.joint_index = static_cast<int>(config.actuators.size());
    b.device_id = id;
    config.actuators.push_back(b);
  }
  return config;
}

std::string temp_path(const char* name) {
  const auto p = std::filesystem::temp_directory_path() /
                 (std::string("animrt_state_") + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove(p);
  return p.string();
}

std::uint8_t read_u8(test::PtyClient& line, std::uint8_t id, std::uint16_t address) {
  const test::Status s = line.transact(test::read(id, address, 1));
  return s.data.size() == 1 ? s.data[0] : 0xEE;
}

TEST(ServoCommissioning, RebootKeepsEepromAndClearsRam) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3}), clock);
  sim.start();
  test::PtyClient line(sim.endpoint());
  EXPECT_EQ(line.transact(test::write(3, xreg::return_delay_time, {20})).error, 0);
  EXPECT_EQ(line.transact(test::write(3, xreg::id, {9})).error, 0);
  EXPECT_EQ(line.transact(test::write(9, xreg::led, {1})).error, 0);
  EXPECT_EQ(line.transact(test::packet(9, dxl::inst::reboot, {})).id, 9);
  EXPECT_EQ(read_u8(line, 9, xreg::return_delay_time), 20);  // EEPROM
  EXPECT_EQ(read_u8(line, 9, xreg::led), 0);                 // RAM
  line.send(test::ping(3));
  EXPECT_TRUE(line.silent());
}

TEST(ServoCommissioning, FactoryResetOptions) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3, 4, 5}), clock);
  sim.start();
  test::PtyClient line(sim.endpoint());
  for (std::uint8_t id : {3, 4, 5}) {
    EXPECT_EQ(line.transact(test::write(id, xreg::return_delay_time, {20})).error, 0);
  }
  // 0x02: all but ID and baud rate.
  EXPECT_EQ(line.transact(test::packet(3, dxl::inst::factory_reset, {0x02})).id, 3);
  EXPECT_EQ(read_u8(line, 3, xreg::return_delay_time), 250);
  auto r = sim.servo_readout(3);
  EXPECT_EQ(r.id, 3);
  EXPECT_EQ(r.baud, 1'000'000);
  // 0x01: all but ID; the answer leaves at the old settings.
  EXPECT_EQ(line.transact(test::packet(4, dxl::inst::factory_reset, {0x01})).id, 4);
  r = sim.servo_readout(4);
  EXPECT_EQ(r.id, 4);
  EXPECT_EQ(r.baud, 57600);
  // 0xFF: everything; the status packet still carries the old ID.
  EXPECT_EQ(line.transact(test::packet(5, dxl::inst::factory_reset, {0xFF})).id, 5);
  r = sim.servo_readout(5);
  EXPECT_EQ(r.id, 1);
  EXPECT_EQ(r.baud, 57600);
  EXPECT_FALSE(r.torque);
  // An unknown option changes nothing.
  EXPECT_EQ(line.transact(test::packet(3, dxl::inst::factory_reset, {0x07})).error,
            static_cast<std::uint8_t>(dxl::StatusError::data_range));
  EXPECT_EQ(sim.servo_readout(3).id, 3);
}

TEST(ServoCommissioning, BroadcastResetAllIsIgnoredFromFirmware42) {
  BusConfig config = dynamixel_bus({3});
  config.sim.firmware_version = 45;
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  test::PtyClient line(sim.endpoint());
  line.send(test::packet(dxl::kBroadcastId, dxl::inst::factory_reset, {0xFF}));
  EXPECT_TRUE(line.silent());
  EXPECT_EQ(sim.servo_readout(3).id, 3);
  line.send(test::packet(dxl::kBroadcastId, dxl::inst::factory_reset, {0x02}));
  EXPECT_TRUE(line.silent());  // a broadcast is never answered
  EXPECT_EQ(read_u8(line, 3, xreg::return_delay_time), 250);
}

TEST(ServoCommissioning, FactoryStartupIsId1At57600WithOneServoPluggedIn) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3, 4, 5}), clock, nullptr, ServoStartup{true, nullptr});
  sim.start();
  for (int id : {3, 4, 5}) {
    const auto r = sim.servo_readout(id);
    EXPECT_EQ(r.id, 1);
    EXPECT_EQ(r.baud, 57600);
  }
  test::PtyClient line(sim.endpoint(), 57600);
  line.send(test::ping(dxl::kBroadcastId));
  EXPECT_EQ(line.read_status(1).size(), 1u);
  EXPECT_TRUE(line.silent(std::chrono::milliseconds(300)));  // one plugged in
  EXPECT_EQ(read_u8(line, 1, xreg::return_delay_time), 250);
}

TEST(ServoCommissioning, StateFileKeepsEepromAcrossRestarts) {
  const std::string path = temp_path("dxl");
  const BusConfig config = dynamixel_bus({3, 4});
  ManualClock clock{0};
  {
    sim::ServoStateFile state(path);
    sim::DynamixelSimBus sim(config, clock, nullptr, ServoStartup{true, &state});
    sim.start();
    test::PtyClient line(sim.endpoint(), 57600);
    EXPECT_EQ(line.transact(test::write(1, xreg::id, {7})).error, 0);
    // Saved on change, before the simulator stops.
    sim::ServoStateFile saved(path);
    EXPECT_EQ(saved.find("legs", 0, sim::kDynamixelX).at(xreg::id), 7);
  }
  sim::ServoStateFile state(path);
  sim::DynamixelSimBus sim(config, clock, nullptr, ServoStartup{true, &state});
  sim.start();
  EXPECT_EQ(sim.servo_readout(3).id, 7);  // kept
  EXPECT_EQ(sim.servo_readout(4).id, 1);  // still new
  std::filesystem::remove(path);
}

TEST(ServoCommissioning, StateFileWithABadLineNamesFileAndLine) {
  const std::string path = temp_path("bad");
  std::ofstream(path) << "# state\nlegs 0 dynamixel2 0a0b\nlegs one dynamixel2 00\n";
  try {
    sim::ServoStateFile state(path);
    FAIL() << "accepted a bad line";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    EXPECT_EQ(e.where().line, 3);
  }
  std::filesystem::remove(path);
}

// An entry that fits no servo of its bus is named at its line when the
// simulator starts (it came up at its defaults, and the file was then
// saved without what it had been given), and the file is left as written.
TEST(ServoCommissioning, AStateEntryThatFitsNoServoIsNamedAtItsLine) {
  const std::string path = temp_path("misfit");
  const BusConfig config = dynamixel_bus({3});
  ManualClock clock{0};
  std::string table(2 * sim::kDynamixelX.eeprom_end, '0');
  const auto with = [&](std::size_t address, const char* hex) {
    std::string t = table;
    t.replace(2 * address, 2, hex);
    return t;
  };
  const std::string good = with(sim::kDynamixelX.baud_address, "01");
  for (const auto& [line, problem] :
       {std::pair{"legs 0 feetech_sts " + good, std::string("is a dynamixel2, found the EEPROM "
                                                            "of a feetech_sts")},
        std::pair{"legs 0 dynamixel2 " + good + "00",
                  std::string("expected " + std::to_string(sim::kDynamixelX.eeprom_end) +
                              " bytes of EEPROM")},
        std::pair{"legs 0 dynamixel2 " + with(sim::kDynamixelX.baud_address, "ff"),
                  std::string("Baud Rate 255 names no baud rate")},
        std::pair{"legs 0 dynamixel2 " + good.substr(0, 2 * sim::kDynamixelX.id_address) + "ff" +
                      good.substr(2 * sim::kDynamixelX.id_address + 2),
                  std::string("id 255 is no servo's")}}) {
    const std::string text = "# state\n" + line + "\n";
    std::ofstream(path) << text;
    sim::ServoStateFile state(path);
    try {
      sim::DynamixelSimBus sim(config, clock, nullptr, ServoStartup{false, &state});
      sim.start();
      ADD_FAILURE() << "started with " << line;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where().file, path);
      EXPECT_EQ(e.where().line, 2);
      EXPECT_NE(std::string(e.what()).find("bus legs servo 0: " + problem), std::string::npos)
          << e.what();
    }
    std::ifstream in(path);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), text);
  }
  std::filesystem::remove(path);
}

// The state is saved by renaming a new file over its path: a path that is
// not a regular file is refused at start, and left as it was (a device given
// as the state, /dev/zero, was once replaced with a file).
TEST(ServoCommissioning, AStatePathThatIsNotARegularFileIsRefusedAndLeftAlone) {
  const std::string fifo = temp_path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string folder = temp_path("folder");
  std::filesystem::create_directory(folder);
  for (const auto& [path, problem] : {std::pair{fifo, std::string("is not a regular file (FIFO)")},
                                      std::pair{folder, std::string("is a directory")}}) {
    try {
      sim::ServoStateFile state(path);
      ADD_FAILURE() << "accepted " << path;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where().file, path);
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(path + ".tmp")) << path;
  }
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_TRUE(std::filesystem::is_directory(folder));
  std::filesystem::remove(fifo);
  std::filesystem::remove(folder);
}

TEST(ServoCommissioning, FeetechEepromIsKeptOnlyWhileUnlocked) {
  BusConfig config;
  config.name = "arm";
  config.protocol = "feetech_sts";
  ActuatorBinding b;
  b.joint = "wrist";
  b.device_id = 1;
  config.actuators.push_back(b);
  const std::string path = temp_path("sts");
  ManualClock clock{0};
  auto write = [](std::uint8_t id, std::uint8_t address, std::uint8_t value) {
    Bytes p = {0xFF, 0xFF, id, 4, ft::inst::write, address, value, 0};
    p.back() = ft::checksum({p.data() + 2, p.size() - 3});
    return p;
  };
  {
    sim::ServoStateFile state(path);
    sim::FeetechSimBus sim(config, ft::Series::sts, clock, ServoStartup{false, &state});
    sim.start();
    test::PtyClient line(sim.endpoint());
    line.send(write(1, ft::reg::sts_lock, 0));
    line.send(write(1, ft::reg::id, 5));  // kept: the lock is open
    line.send(write(5, ft::reg::sts_lock, 1));
    line.send(write(5, ft::reg::return_delay, 9));  // applied, not kept
    EXPECT_EQ(line.read_raw(24).size(), 24u);       // four status packets
    EXPECT_EQ(sim.servo_readout(1).id, 5);
    sim.set_device_plugged(0, false);
    sim.set_device_plugged(0, true);  // a power cycle
  }
  sim::ServoStateFile state(path);
  EXPECT_EQ(state.find("arm", 0, sim::kFeetechSts).at(ft::reg::id), 5);
  EXPECT_EQ(state.find("arm", 0, sim::kFeetechSts).at(ft::reg::return_delay), 0);
  sim::FeetechSimBus sim(config, ft::Series::sts, clock, ServoStartup{false, &state});
  EXPECT_EQ(sim.servo_readout(1).id, 5);
  std::filesystem::remove(path);
}

std::int32_t read_i32(test::PtyClient& line, std::uint8_t id, std::uint16_t address) {
  const test::Status s = line.transact(test::read(id, address, 4));
  return s.data.size() == 4 ? static_cast<std::int32_t>(dxl::get_u32(s.data.data())) : -999999;
}

TEST(ServoCommissioning, HomingOffsetShiftsPresentAndGoalPosition) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3}), clock);
  sim.start();
  test::PtyClient line(sim.endpoint());
  sim.hand_move(3, 1000);
  EXPECT_EQ(line.transact(test::write_u32(3, 20, 500)).error, 0);  // Homing Offset
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 1500);
  EXPECT_EQ(sim.servo_readout(3).ticks, 1500);
  // Torque on holds where it is; a goal is in the offset frame too.
  EXPECT_EQ(line.transact(test::write(3, xreg::torque_enable, {1})).error, 0);
  EXPECT_EQ(line.transact(test::write_u32(3, xreg::goal_position, 1700)).error, 0);
  clock.advance(2'000'000'000);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 1700);
}

TEST(ServoCommissioning, ExtendedPositionModeTurnsPastOneTurn) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3}), clock);
  sim.start();
  test::PtyClient line(sim.endpoint());
  EXPECT_EQ(line.transact(test::write_u32(3, xreg::goal_position, 9000)).error,
            static_cast<std::uint8_t>(dxl::StatusError::data_limit));  // mode 3: limits
  EXPECT_EQ(line.transact(test::write(3, xreg::operating_mode, {4})).error, 0);
  EXPECT_EQ(line.transact(test::write(3, xreg::torque_enable, {1})).error, 0);
  EXPECT_EQ(line.transact(test::write_u32(3, xreg::goal_position, 9000)).error, 0);
  clock.advance(20'000'000'000);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 9000);
  EXPECT_EQ(line.transact(test::write_u32(3, xreg::goal_position, 2'000'000)).error,
            static_cast<std::uint8_t>(dxl::StatusError::data_limit));
}

// Present Position = the count of the shaft's ticks + Homing Offset; the
// count goes on across turns and starts again from the shaft's angle within
// its turn at a Reboot, a power cycle, entering position mode and torque on
// in it (X-series manual, Present Position and Homing Offset).
TEST(ServoCommissioning, TheCountOfTurnsStartsAgainWithinOneTurn) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3}), clock);
  sim.start();
  test::PtyClient line(sim.endpoint());
  EXPECT_EQ(line.transact(test::write(3, xreg::operating_mode, {4})).error, 0);
  sim.hand_move(3, 9000);  // two turns and 808 ticks, torque off
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 9000);
  // Homing Offset (20) moves what it reads, not the shaft.
  EXPECT_EQ(line.transact(test::write_u32(3, 20, static_cast<std::uint32_t>(-100))).error, 0);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 8900);
  EXPECT_EQ(line.transact(test::packet(3, dxl::inst::reboot, {})).id, 3);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 808 - 100);
  sim.hand_move(3, 708 + 4096 * 3);  // turned three more turns, then power cycled
  sim.set_device_plugged(0, false);
  sim.set_device_plugged(0, true);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 708);
  // Torque off in mode 4 and back: the count goes on.
  sim.hand_move(3, 708 - 4096);
  EXPECT_EQ(line.transact(test::write(3, xreg::torque_enable, {1})).error, 0);
  EXPECT_EQ(line.transact(test::write(3, xreg::torque_enable, {0})).error, 0);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 708 - 4096);
  // Position control mode counts within one turn from its start.
  EXPECT_EQ(line.transact(test::write(3, xreg::operating_mode, {3})).error, 0);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 708);
}

TEST(ServoCommissioning, AWeakCurrentBasedPositionHoldYieldsToAHand) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3}), clock);
  sim.start();
  test::PtyClient line(sim.endpoint());
  sim.hand_move(3, 2000);
  EXPECT_EQ(line.transact(test::write(3, xreg::operating_mode, {5})).error, 0);
  // Goal Current 100 of the Current Limit 1193: weaker than a hand.
  EXPECT_EQ(line.transact(test::write(3, xreg::goal_current, {100, 0})).error, 0);
  EXPECT_EQ(line.transact(test::write(3, xreg::torque_enable, {1})).error, 0);
  sim.hand_move(3, 2300);  // the hand holds it there against the servo's pull
  clock.advance(1'000'000'000);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 2300);
  // The goal comes to the hand: it lets go, and the servo holds the joint.
  EXPECT_EQ(line.transact(test::write_u32(3, xreg::goal_position, 2302)).error, 0);
  clock.advance(1'000'000'000);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 2302);
  // Let go while the goal is elsewhere, the weak torque still moves it there.
  sim.hand_move(3, 2400);
  EXPECT_EQ(line.transact(test::write(3, xreg::torque_enable, {0})).error, 0);
  EXPECT_EQ(line.transact(test::write(3, xreg::torque_enable, {1})).error, 0);
  clock.advance(1'000'000'000);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 2302);
  // Half the Current Limit: stronger than a hand.
  EXPECT_EQ(line.transact(test::write(3, xreg::goal_current, {0x54, 0x02})).error, 0);  // 596
  EXPECT_THROW(sim.hand_move(3, 2100), std::logic_error);
  EXPECT_EQ(read_i32(line, 3, xreg::present_position), 2302);
}

TEST(ServoCommissioning, AFeetechUnderALowTorqueLimitYieldsToAHand) {
  BusConfig config;
  config.name = "arm";
  config.protocol = "feetech_sts";
  ActuatorBinding b;
  b.joint = "wrist";
  b.device_id = 1;
  config.actuators.push_back(b);
  ManualClock clock{0};
  sim::FeetechSimBus sim(config, ft::Series::sts, clock, ServoStartup{});
  sim.start();
  test::PtyClient line(sim.endpoint());
  auto write = [&line](std::uint8_t address, Bytes data) {  // STS: little-endian
    Bytes p = {0xFF, 0xFF, 1, static_cast<std::uint8_t>(data.size() + 3), ft::inst::write, address};
    p.insert(p.end(), data.begin(), data.end());
    p.push_back(0);
    p.back() = ft::checksum({p.data() + 2, p.size() - 3});
    line.send(p);
    EXPECT_EQ(line.read_raw(6).size(), 6u);  // its status packet
  };
  sim.hand_move(1, 2000);
  write(ft::reg::sts_torque_limit, {100, 0});  // 10 % of full torque: weaker than a hand
  write(ft::reg::torque_enable, {1});
  sim.hand_move(1, 2300);  // held there against the servo's pull to 2000
  clock.advance(1'000'000'000);
  EXPECT_EQ(sim.servo_readout(1).ticks, 2300);
  write(ft::reg::goal_position, {0xFE, 0x08});  // 2302: the hand lets go, the servo holds
  clock.advance(1'000'000'000);
  EXPECT_EQ(sim.servo_readout(1).ticks, 2302);
  write(ft::reg::sts_torque_limit, {0xF4, 0x01});  // 50 %: stronger than a hand
  EXPECT_THROW(sim.hand_move(1, 2100), std::logic_error);
  EXPECT_EQ(sim.servo_readout(1).ticks, 2302);
}

TEST(ServoCommissioning, FeetechFactoryStartupIsId1At1Mbaud) {
  BusConfig config;
  config.name = "arm";
  config.protocol = "feetech_sts";
  config.baud = 500'000;
  for (int id : {2, 3}) {
    ActuatorBinding b;
    b.joint = "j" + std::to_string(id);
    b.device_id = id;
    config.actuators.push_back(b);
  }
  ManualClock clock{0};
  sim::FeetechSimBus sim(config, ft::Series::sts, clock, ServoStartup{true, nullptr});
  EXPECT_EQ(sim.servo_readout(2).id, 1);
  EXPECT_EQ(sim.servo_readout(2).baud, 1'000'000);
  EXPECT_EQ(sim.servo_readout(3).id, 1);
}

}  // namespace
}  // namespace animrt
