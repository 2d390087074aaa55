// device_watchdog_ms (and the CiA 402 keys of the drives' guard) on CAN
// buses: the default for the loop rate, off only when asked, and one error
// with file:line:column for a value out of range.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/protocol.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "support/files.hpp"

namespace animrt::can_watchdog_config_test {
namespace {

namespace fs = std::filesystem;

int drive_ms(const RobotConfig& c) {
  return std::any_cast<Cia402BusOptions>(c.buses[0].options).device_watchdog_ms;
}
int motor_ms(const RobotConfig& c) {
  return std::any_cast<MitBusOptions>(c.buses[1].options).device_watchdog_ms;
}

class CanWatchdogConfig : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("animrt_can_watchdog_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    write_file(dir_ / "gaits" / "gait.yaml", "# a gait\n");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path() const { return (dir_ / "robots" / "robot.yaml").string(); }

  // A drive bus and a motor bus; `drive` and `motor` are extra keys (one
  // line each, at column 5), `rate` the loop rate.
  RobotConfig load(const std::string& drive, const std::string& motor = "", int rate = 200) {
    std::string text = "name: t\nloop: {rate_hz: " + std::to_string(rate) +
                       "}\n"
                       "buses:\n"
                       "  drive:\n"
                       "    protocol: cia402\n"
                       "    interface: can0\n" +
                       (drive.empty() ? "" : "    " + drive + "\n") +
                       "  motors:\n"
                       "    protocol: mit\n"
                       "    interface: can1\n" +
                       (motor.empty() ? "" : "    " + motor + "\n") +
                       "joints:\n"
                       "  a:\n"
                       "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                       "acceleration_dps2: 1000}\n"
                       "    actuator: {bus: drive, node_id: 3}\n"
                       "  b:\n"
                       "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                       "acceleration_dps2: 1000}\n"
                       "    actuator: {bus: motors, id: 1, model: ak80-9, kp: 10, kd: 1}\n"
                       "motion: {type: gait, file: ../gaits/gait.yaml}\n";
    write_file(path(), text);
    return load_robot_config(path());
  }
  std::string error_of(const std::string& drive, const std::string& motor = "", int rate = 200) {
    try {
      (void)load(drive, motor, rate);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  fs::path dir_;
};

TEST_F(CanWatchdogConfig, DefaultIsTheLargerOf100MsAndFiveLoopPeriods) {
  RobotConfig c = load("");
  EXPECT_EQ(drive_ms(c), 100);
  EXPECT_EQ(motor_ms(c), 100);
  c = load("", "", 40);  // 25 ms periods
  EXPECT_EQ(drive_ms(c), 125);
  EXPECT_EQ(motor_ms(c), 125);
  c = load("", "", 30);  // 33.3 ms periods
  EXPECT_EQ(drive_ms(c), 167);
  const auto o = std::any_cast<Cia402BusOptions>(c.buses[0].options);
  EXPECT_EQ(o.abort_connection, AbortConnection::quick_stop);
  EXPECT_EQ(o.host_node_id, 127);
}

TEST_F(CanWatchdogConfig, SetOrOffOnlyWhenAsked) {
  RobotConfig c = load("device_watchdog_ms: 120", "device_watchdog_ms: 30");
  EXPECT_EQ(drive_ms(c), 120);
  EXPECT_EQ(motor_ms(c), 30);
  c = load("device_watchdog_ms: off", "device_watchdog_ms: 0");
  EXPECT_EQ(drive_ms(c), 0);
  EXPECT_EQ(motor_ms(c), 0);
  c = load("abort_connection: fault", "");
  EXPECT_EQ(std::any_cast<Cia402BusOptions>(c.buses[0].options).abort_connection,
            AbortConnection::fault);
  c = load("abort_connection: disable_voltage", "");
  EXPECT_EQ(std::any_cast<Cia402BusOptions>(c.buses[0].options).abort_connection,
            AbortConnection::disable_voltage);
  c = load("host_node_id: 1", "");
  EXPECT_EQ(std::any_cast<Cia402BusOptions>(c.buses[0].options).host_node_id, 1);
}

TEST_F(CanWatchdogConfig, OutOfRangeIsAnErrorAtTheKey) {
  EXPECT_EQ(error_of("device_watchdog_ms: 70000"),
            path() +
                ":7:25: buses.drive.device_watchdog_ms: expected off, 0, or milliseconds "
                "from 1 to 65535 (CiA 402 consumer time), found \"70000\"");
  EXPECT_EQ(error_of("", "device_watchdog_ms: -5"),
            path() +
                ":10:25: buses.motors.device_watchdog_ms: expected off, 0, or milliseconds "
                "from 1 to 60000 (the motors' CAN timeout), found \"-5\"");
  EXPECT_EQ(error_of("device_watchdog_ms: soon"),
            path() +
                ":7:25: buses.drive.device_watchdog_ms: expected off, 0, or milliseconds "
                "from 1 to 65535 (CiA 402 consumer time), found \"soon\"");
  // The host's cycle feeds the guard: it must outlast three loop periods.
  EXPECT_EQ(error_of("device_watchdog_ms: 10"),
            path() +
                ":7:25: buses.drive.device_watchdog_ms: expected off or at least three loop "
                "periods (15 ms at loop.rate_hz 200), found \"10\"");
  EXPECT_EQ(error_of("", "device_watchdog_ms: 14"),
            path() +
                ":10:25: buses.motors.device_watchdog_ms: expected off or at least three loop "
                "periods (15 ms at loop.rate_hz 200), found \"14\"");
  EXPECT_EQ(error_of("abort_connection: halt"),
            path() +
                ":7:23: buses.drive.abort_connection: expected quick_stop, disable_voltage or "
                "fault (the drive's reaction to a missed host heartbeat, object 6007h), found "
                "\"halt\"");
  EXPECT_EQ(error_of("host_node_id: 3"),
            path() +
                ":14:37: joints.a.actuator.node_id: node id 3 is the host's (bus drive "
                "host_node_id, default 127): its heartbeats would be taken for the drive's");
}

TEST_F(CanWatchdogConfig, TheHostHeartbeatCountsInTheBusLoad) {
  const RobotConfig on = load("");
  const RobotConfig off = load("device_watchdog_ms: off");
  const Protocol* cia402 = find_protocol("cia402");
  // SYNC 55 + RPDO and TPDO 115 each, worst-case stuffing; heartbeat 65.
  EXPECT_EQ(cia402->wire_bits_per_cycle(off.buses[0]), 285.0);
  EXPECT_EQ(cia402->wire_bits_per_cycle(on.buses[0]), 350.0);
}

TEST_F(CanWatchdogConfig, ValidateSaysWhatEachBusHas) {
  RobotConfig c = load("", "");
  // The drives are set at activate: nothing to say; the motors' timeout is
  // set by hand, so it is named with its number of cycles.
  std::vector<std::string> notes = device_guard_notes(c);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0],
            "bus motors (mit): the motors go limp 100 ms after the last command only if each "
            "motor's CAN timeout is set to that in its serial setup menu (4000 cycles at 40 "
            "kHz): animrt cannot set or read it over CAN");
  c = load("device_watchdog_ms: off", "device_watchdog_ms: off");
  notes = device_guard_notes(c);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0],
            "bus drive (cia402): no device-side guard (device_watchdog_ms: off): if the host "
            "dies, the drives stay in Operation Enabled at their last target");
  EXPECT_EQ(notes[1],
            "bus motors (mit): no device-side guard (device_watchdog_ms: off): if the host dies, "
            "the motors keep their last command (position, gains, torque)");
}

}  // namespace
}  // namespace animrt::can_watchdog_config_test
