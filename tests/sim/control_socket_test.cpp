// The control interface of `animrt sim`: a hand turns a limp servo through
// the socket and the runtime's bus reads where it went, a hand path steps
// on with the servo's reads; a servo with torque on refuses the hand; an
// unplugged servo is silent until plugged in again.

#include "animrt/sim/control_socket.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/bridge/feetech/feetech_bus.hpp"
#include "animrt/sim/dynamixel_sim_bus.hpp"
#include "animrt/sim/feetech/feetech_sim_bus.hpp"
#include "sim/pty_client.hpp"

namespace animrt {
namespace {

BusConfig dynamixel_bus(const std::string& name, std::vector<int> ids) {
  BusConfig config;
  config.name = name;
  config.protocol = "dynamixel2";
  config.timeout_s = 0.1;
  for (int id : ids) {
    ActuatorBinding b;
    b.joint = "joint" + std::to_string(id);
    b.joint_index = static_cast<int>(config.actuators.size());
    b.device_id = id;
    config.actuators.push_back(b);
  }
  return config;
}

// The tiny client: one line out, one line back.
class LineClient {
 public:
  explicit LineClient(const std::string& path) {
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
      throw std::runtime_error("cannot connect to " + path);
    }
  }
  ~LineClient() { ::close(fd_); }
  std::string ask(const std::string& line) {
    const std::string out = line + "\n";
    if (::write(fd_, out.data(), out.size()) != static_cast<ssize_t>(out.size())) return "";
    std::string reply;
    char c = 0;
    while (::read(fd_, &c, 1) == 1 && c != '\n') reply += c;
    return reply;
  }

 private:
  int fd_ = -1;
};

std::string socket_path(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string("animrt_control_") + name + "_" + std::to_string(::getpid())))
      .string();
}

TEST(ControlSocket, HandTurnsALimpServoAndTheRuntimeReadsIt) {
  const BusConfig config = dynamixel_bus("legs", {3, 4});
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  const std::string path = socket_path("hand");
  {
    sim::ControlSocket control(path, {{"legs", &sim}});
    LineClient client(path);
    DynamixelBus bus(config, open_serial(sim.endpoint(), 1'000'000));
    bus.configure();  // torque stays off: the servos are limp

    EXPECT_EQ(client.ask("hand legs 4 2600"), "ok");
    EXPECT_EQ(client.ask("get legs 4"), "ok ticks=2600 torque=0 id=4 baud=1000000");
    std::vector<double> q(2, 99.0);
    bus.read(q);
    EXPECT_NEAR(q[1], config.actuators[1].to_rad(2600), 1e-9);

    // The test aid: a hand path takes its next step once the servo has
    // answered 2 reads of its position at the one before; what is not a
    // read of the servo (a `get`) does not move it on.
    const auto reads_ticks = [&](int reads) {
      std::vector<int> out;
      for (int k = 0; k < reads; ++k) {
        bus.read(q);
        out.push_back(config.actuators[1].to_ticks(q[1]));
      }
      return out;
    };
    EXPECT_EQ(client.ask("hand-path legs 4 2 100 -200 300"), "ok");
    EXPECT_EQ(client.ask("get legs 4"), "ok ticks=100 torque=0 id=4 baud=1000000");
    EXPECT_EQ(client.ask("get legs 4"), "ok ticks=100 torque=0 id=4 baud=1000000");
    EXPECT_EQ(reads_ticks(7), (std::vector<int>{100, 100, -200, -200, 300, 300, 300}));
    // A new hand move ends a path.
    EXPECT_EQ(client.ask("hand-path legs 4 1 500 600"), "ok");
    EXPECT_EQ(client.ask("hand legs 4 2600"), "ok");
    EXPECT_EQ(reads_ticks(3), (std::vector<int>{2600, 2600, 2600}));
    EXPECT_EQ(client.ask("hand-path legs 4 0 1 2").rfind("error: '0' is not a count", 0), 0u);
    EXPECT_EQ(client.ask("hand-path legs 4 1").rfind("error: usage: hand-path", 0), 0u);

    bus.activate();  // torque on: the servo holds, a hand cannot turn it
    EXPECT_EQ(client.ask("get legs 4"), "ok ticks=2600 torque=1 id=4 baud=1000000");
    EXPECT_EQ(client.ask("hand legs 4 1000"), "error: torque is on");
    EXPECT_EQ(client.ask("hand-path legs 4 1 1000 1100"), "error: torque is on");
    bus.read(q);
    EXPECT_NEAR(q[1], config.actuators[1].to_rad(2600), 1e-9);
    bus.deactivate();

    EXPECT_EQ(client.ask("hand arms 4 10"), "error: no bus 'arms'");
    EXPECT_EQ(client.ask("hand legs 9 10").rfind("error: no device 9", 0), 0u);
    EXPECT_EQ(client.ask("hand legs 4 x").rfind("error: ", 0), 0u);
    EXPECT_EQ(client.ask("spin legs 4").rfind("error: unknown command", 0), 0u);
    EXPECT_EQ(client.ask("plug legs 2").rfind("error: no device #2", 0), 0u);
  }
  EXPECT_FALSE(std::filesystem::exists(path));  // removed when the socket closes
}

TEST(ControlSocket, UnpluggedServoIsSilentUntilPluggedInAgain) {
  const BusConfig config = dynamixel_bus("legs", {3, 4});
  ManualClock clock{0};
  sim::DynamixelSimBus sim(config, clock);
  sim.start();
  const std::string path = socket_path("plug");
  sim::ControlSocket control(path, {{"legs", &sim}});
  LineClient client(path);
  test::PtyClient line(sim.endpoint());
  line.send(test::write(3, dxl::xreg::torque_enable, {1}));
  ASSERT_EQ(line.read_status(1).size(), 1u);

  EXPECT_EQ(client.ask("unplug legs 0"), "ok");
  line.send(test::ping(3));
  EXPECT_TRUE(line.silent());
  EXPECT_EQ(client.ask("plug legs 0"), "ok");
  EXPECT_EQ(line.transact(test::ping(3)).id, 3);
  // Powered up again: RAM at its defaults, torque off.
  EXPECT_NE(client.ask("get legs 3").find(" torque=0 id=3 "), std::string::npos);
}

TEST(ControlSocket, HandTurnsALimpFeetechServo) {
  BusConfig config;
  config.name = "arm";
  config.protocol = "feetech_sts";
  config.timeout_s = 0.1;
  ActuatorBinding b;
  b.joint = "wrist";
  b.device_id = 1;
  config.actuators.push_back(b);
  ManualClock clock{0};
  sim::FeetechSimBus sim(config, ft::Series::sts, clock);
  sim.start();
  FeetechBus bus(config, ft::Series::sts, open_serial(sim.endpoint(), 1'000'000));
  bus.configure();
  sim.hand_move(1, 3000);
  std::vector<double> q(1, 99.0);
  bus.read(q);
  EXPECT_NEAR(q[0], config.actuators[0].to_rad(3000), 1e-9);
  EXPECT_EQ(sim.servo_readout(1).ticks, 3000);
  bus.activate();
  EXPECT_THROW(sim.hand_move(1, 100), std::logic_error);
  bus.deactivate();
}

}  // namespace
}  // namespace animrt
