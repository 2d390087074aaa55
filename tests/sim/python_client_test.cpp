// The simulator must serve any Protocol 2.0 client, not just ours: a small
// Python implementation of the packet format (its own CRC) over pyserial.

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <memory>
#include <string>

#include "animrt/sim/dynamixel_sim_bus.hpp"

namespace animrt {
namespace {

// Debian's interpreter: the one on PATH may not see python3-serial.
constexpr const char* kPython = "/usr/bin/python3";

std::string run(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) {
    status = -1;
    return out;
  }
  std::array<char, 256> buf{};
  while (std::fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
  status = ::pclose(pipe);
  return out;
}

TEST(DynamixelSimPythonClient, PingAndReadFromPyserial) {
  ASSERT_EQ(::access(kPython, X_OK), 0) << kPython << " not found";
  int status = 0;
  run(std::string(kPython) + " -c 'import serial' 2>/dev/null", status);
  ASSERT_EQ(status, 0) << "python3-serial not installed (scripts/install-deps.sh installs it)";

  ManualClock clock;
  BusConfig config;
  config.name = "head";
  config.protocol = "dynamixel2";
  ActuatorBinding b;
  b.joint = "neck";
  b.device_id = 1;
  config.actuators.push_back(b);
  sim::DynamixelSimBus bus(config, clock);
  bus.start();

  const std::string script = std::string(ANIMRT_SOURCE_DIR) + "/tests/sim/dxl_python_client.py";
  const std::string out =
      run(std::string(kPython) + " " + script + " " + bus.endpoint() + " 2>&1", status);
  ASSERT_EQ(status, 0) << out;
  const std::int32_t position = b.to_ticks(bus.device_position(1));
  EXPECT_EQ(out, "ping 1 0 1030 38\nread 1 0 " + std::to_string(position) + "\n");
  EXPECT_EQ(bus.stats().crc_errors, 0u);
}

}  // namespace
}  // namespace animrt
