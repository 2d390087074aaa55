// Standard Modbus masters talk to the simulated drives: mbpoll over TCP and
// pymodbus over TCP and RTU (both from Debian).

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "animrt/runtime/robot_config.hpp"
#include "animrt/sim/modbus/modbus_sim_bus.hpp"

namespace animrt {
namespace {

const std::string kMapsDir = std::string(ANIMRT_SOURCE_DIR) + "/configs/modbus/";

RobotConfig drives(const std::string& protocol) {
  const std::string path = ::testing::TempDir() + "/peer_" +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                           ".yaml";
  std::ofstream(path)
      << "name: drives\nloop: {rate_hz: 100}\nbuses:\n  drives:\n    protocol: " << protocol
      << "\n    port: "
      << (protocol == "modbus-tcp" ? "127.0.0.1:1502" : "/dev/null")
      // 230400 baud: two drives' traffic fits a 100 Hz cycle on the wire.
      << "\n    parity: none\n    baud: 230400\n"
      << "joints:\n  pan:\n"
         "    limits: {min_deg: -90, max_deg: 90, velocity_dps: 100, acceleration_dps2: 500}\n"
         "    actuator: {bus: drives, slave: 1, map: "
      << kMapsDir
      << "position_drive.yaml}\n  lean:\n"
         "    limits: {min_deg: -20, max_deg: 20, velocity_dps: 20, acceleration_dps2: 100}\n"
         "    actuator: {bus: drives, slave: 2, map: "
      << kMapsDir << "linear_actuator.yaml, m_per_rad: 0.1, zero_m: 0.05}\n"
      << "motion: {type: gait, file: " << path << "}\n";
  std::string text;
  if (protocol == "modbus-tcp") {
    // parity and baud are RTU keys
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
    text.replace(text.find("    parity: none\n    baud: 230400\n"), 33, "");
    std::ofstream(path) << text;
  }
  return load_robot_config(path);
}

std::string run(const std::string& command) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return "popen failed";
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  ::pclose(p);
  return out;
}

std::map<std::string, std::string> lines(const std::string& out) {
  std::map<std::string, std::string> m;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    const auto sp = line.find(' ');
    if (sp != std::string::npos) m[line.substr(0, sp)] = line.substr(sp + 1);
  }
  return m;
}

// A missing peer is a failure that says what to install, never a skip.
void require(const std::string& probe, const std::string& what) {
  ASSERT_EQ(std::system((probe + " > /dev/null 2>&1").c_str()), 0)
      << what << " not found (scripts/install-deps.sh installs it)";
}

void expect_pymodbus(const std::string& kind, const std::string& where) {
  require("/usr/bin/python3 -c 'import pymodbus'", "python3-pymodbus");
  const std::string out = run("/usr/bin/python3 " + std::string(ANIMRT_SOURCE_DIR) +
                              "/tests/modbus/pymodbus_client.py " + kind + " " + where);
  auto m = lines(out);
  // lean starts at initial_offset_rad(2) = -4 deg: 0.05 + 0.1 * -0.0698 m = 4302 counts
  EXPECT_EQ(m["present_status"], "4302 0") << out;
  EXPECT_EQ(m["exception_value"], "3") << out;
  EXPECT_EQ(m["exception_address"], "2") << out;
  EXPECT_EQ(m["write_ok"], "yes") << out;
  EXPECT_EQ(m["goal"], "5000") << out;
}

TEST(ModbusPeers, PymodbusOverTcp) {
  MonotonicClock clock;
  RobotConfig c = drives("modbus-tcp");
  sim::ModbusSimBus sim(c.buses[0], clock);
  sim.start();
  expect_pymodbus("tcp", sim.endpoint());
}

TEST(ModbusPeers, PymodbusOverRtu) {
  MonotonicClock clock;
  RobotConfig c = drives("modbus-rtu");
  sim::ModbusSimBus sim(c.buses[0], clock);
  sim.start();
  expect_pymodbus("rtu", sim.endpoint());
}

TEST(ModbusPeers, MbpollReadsInputRegistersAndWritesTheEnableCoil) {
  MonotonicClock clock;
  RobotConfig c = drives("modbus-tcp");
  sim::ModbusSimBus sim(c.buses[0], clock);
  sim.start();
  require("command -v mbpoll", "mbpoll");
  const std::string port = sim.endpoint().substr(sim.endpoint().rfind(':') + 1);
  // Slave 1: present (int32, 2 words) and status at input registers 0..2.
  const std::string read = run("mbpoll -m tcp -p " + port + " -a 1 -t 3 -0 -r 0 -c 3 -1 127.0.0.1");
  // initial_offset_rad(1) = +3 deg = 0.05236 rad = 524 counts of 0.0001 rad.
  EXPECT_NE(read.find("[0]: \t0"), std::string::npos) << read;
  EXPECT_NE(read.find("[1]: \t524"), std::string::npos) << read;
  EXPECT_NE(read.find("[2]: \t0"), std::string::npos) << read;
  const std::string write = run("mbpoll -m tcp -p " + port + " -a 1 -t 0 -0 -r 0 127.0.0.1 1");
  EXPECT_NE(write.find("Written 1 references"), std::string::npos) << write;
  const std::string bad = run("mbpoll -m tcp -p " + port + " -a 1 -t 3 -0 -r 40 -c 1 -1 127.0.0.1");
  EXPECT_NE(bad.find("Illegal data address"), std::string::npos) << bad;
}

}  // namespace
}  // namespace animrt
