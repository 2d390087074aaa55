// The Maestro bus driver against simulated boards over a real pty, and the
// robot-file checks of the maestro protocol.

#include "animrt/bridge/maestro/maestro_bus.hpp"

#include <gtest/gtest.h>

#include <any>
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "animrt/core/joint.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/sim/maestro/maestro_sim_bus.hpp"

namespace animrt {
namespace {

std::string write_robot(const std::string& name, const std::string& text) {
  const std::string path =
      ::testing::TempDir() + "/" +
      std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

// Three servos: eyes on channels 0 and 1 (a block), jaw on 4 (mirrored).
std::string robot_text(const std::string& bus_extra = "", const std::string& jaw_extra = "") {
  return R"(name: face
loop: {rate_hz: 100}
buses:
  face:
    protocol: maestro
    port: /dev/null
)" + bus_extra +
         R"(joints:
  eye_pan:
    limits: {min_deg: -30, max_deg: 30, velocity_dps: 300, acceleration_dps2: 3000}
    actuator: {bus: face, channel: 0, deg_per_us: 0.09}
  eye_tilt:
    limits: {min_deg: -20, max_deg: 20, velocity_dps: 300, acceleration_dps2: 3000}
    actuator: {bus: face, channel: 1, deg_per_us: 0.09}
  jaw:
    limits: {min_deg: 0, max_deg: 25, velocity_dps: 200, acceleration_dps2: 2000}
    actuator: {bus: face, channel: 4, deg_per_us: -0.09, neutral_us: 1700)" +
         jaw_extra + R"(}
motion: {type: gait, file: )" +
         std::string(ANIMRT_SOURCE_DIR) + R"(/configs/gaits/walk.yaml}
)";
}

RobotConfig load(const std::string& text, const std::string& name = "robot.yaml") {
  return load_robot_config(write_robot(name, text));
}

std::string error_of(const std::string& text) {
  try {
    load(text, "bad.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

struct Rig {
  ManualClock clock;
  RobotConfig config;
  std::unique_ptr<sim::MaestroSimBus> sim;
  std::unique_ptr<ActuatorBus> bus;
  explicit Rig(const std::string& bus_extra = "") {
    config = load(robot_text(bus_extra));
    BusConfig& b = config.buses[0];
    b.timeout_s = 0.2;  // a loaded machine may hold the simulated board off the CPU a while
    sim = std::make_unique<sim::MaestroSimBus>(b, clock);
    sim->start();
    b.port = sim->endpoint();
    bus = make_bus(b);
  }
};

TEST(MaestroConfig, CalibrationMapsToQuarterMicroseconds) {
  const RobotConfig c = load(robot_text());
  const auto& jaw = c.buses[0].actuators[2];
  EXPECT_EQ(jaw.device_id, 4);
  EXPECT_EQ(jaw.zero_ticks, 6800);  // 1700 us
  EXPECT_EQ(jaw.direction, -1);
  // 10 deg of jaw = 111.1 us less pulse = 444.4 quarter-us.
  EXPECT_EQ(jaw.to_ticks(deg_to_rad(10)), 6800 - 444);
}

TEST(MaestroConfig, ErrorsNameFileLineAndKey) {
  // The jaw's 25 deg maps to 1700 - 277.8 = 1422 us: fine. Its 0 deg at
  // neutral is fine. Now make the range too narrow.
  EXPECT_NE(error_of(robot_text("", ", max_us: 1600")).find("neutral_us"), std::string::npos);
  const std::string narrow = error_of(robot_text("", ", min_us: 1500"));
  EXPECT_NE(narrow.find("bad.yaml:15:"), std::string::npos) << narrow;
  EXPECT_NE(narrow.find("joints.jaw.limits.max_deg: 25 deg maps to 1422.2"), std::string::npos)
      << narrow;
  EXPECT_NE(narrow.find("outside min_us..max_us (1500..2000)"), std::string::npos) << narrow;

  std::string text = robot_text();
  text.replace(text.find("channel: 4"), 10, "channel: 12");
  const std::string channel = error_of(text);
  EXPECT_NE(channel.find("joints.jaw.actuator.channel: expected a channel from 0 to 11"),
            std::string::npos)
      << channel;

  text = robot_text();
  text.replace(text.find("channel: 1,"), 11, "channel: 0,");
  EXPECT_NE(error_of(text).find("channel 0 is already used by joint eye_pan"), std::string::npos);

  text = robot_text();
  text.replace(text.find("deg_per_us: 0.09}"), 17, "speed: 5}");
  EXPECT_NE(error_of(text).find("joints.eye_pan.actuator: missing key rad_per_us or deg_per_us"),
            std::string::npos)
      << error_of(text);

  EXPECT_NE(error_of(robot_text("    device_number: 3\n"))
                .find("buses.face.device_number: device_number needs serial_protocol: pololu"),
            std::string::npos);
  EXPECT_NE(error_of(robot_text("    board: maxi\n")).find("expected micro6, mini12"),
            std::string::npos);
}

TEST(MaestroBus, ReadsTheBoardsOutputAndWritesBlocksOfTargets) {
  Rig r;
  r.bus->configure();
  std::vector<double> pos(3, 99.0);
  r.bus->read(pos);
  // Off channels are reported at their neutral pulse.
  EXPECT_DOUBLE_EQ(pos[0], 0.0);
  EXPECT_DOUBLE_EQ(pos[2], 0.0);
  for (const auto& d : r.bus->devices()) EXPECT_TRUE(d.open_loop);
  r.bus->activate();
  EXPECT_EQ(r.sim->pulse(0), 6000);
  EXPECT_EQ(r.sim->pulse(4), 6800);

  const std::vector<double> goal{deg_to_rad(9), deg_to_rad(-4.5), deg_to_rad(18)};
  r.bus->write(goal);
  r.clock.advance(10'000'000);
  r.bus->read(pos);
  EXPECT_EQ(r.sim->pulse(0), 6400);  // +100 us
  EXPECT_EQ(r.sim->pulse(1), 5800);
  EXPECT_EQ(r.sim->pulse(4), 6000);  // 18 deg at -0.09 deg/us = -200 us
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(pos[i], goal[i], deg_to_rad(0.025)) << i;
  for (const auto& d : r.bus->devices()) {
    EXPECT_EQ(d.health, DeviceHealth::ok);
    EXPECT_EQ(d.timeouts, 0u);
    EXPECT_GE(d.transactions, 2u);
  }
  r.bus->deactivate();
  r.bus->read(pos);               // answered: the board has handled everything before it
  EXPECT_EQ(r.sim->pulse(0), 0);  // pulses off
}

TEST(MaestroBus, GoalsAreClampedIntoTheJointLimitsAndNaNHolds) {
  Rig r;
  r.bus->configure();
  r.bus->activate();
  std::vector<double> pos(3, 0.0);
  // eye_pan is limited to +-30 degrees: 30 / 0.09 = 333.3 us past neutral.
  r.bus->write(std::vector<double>{deg_to_rad(80), deg_to_rad(-4.5), deg_to_rad(18)});
  r.clock.advance(10'000'000);
  r.bus->read(pos);
  EXPECT_EQ(r.sim->pulse(0), 6000 + 1333);
  r.bus->write(std::vector<double>{std::nan(""), deg_to_rad(-4.5), deg_to_rad(18)});
  r.clock.advance(10'000'000);
  r.bus->read(pos);
  EXPECT_EQ(r.sim->pulse(0), 6000 + 1333);
}

TEST(MaestroBus, BoardErrorsAreHardwareErrorsOfEveryChannel) {
  Rig r;
  r.bus->configure();
  r.bus->activate();
  std::vector<double> pos(3);
  r.sim->set_device_hardware_error(4, 0x20);  // serial timeout
  r.bus->read(pos);
  for (const auto& d : r.bus->devices()) {
    EXPECT_EQ(d.health, DeviceHealth::hardware_error);
    EXPECT_EQ(d.hardware_error_status, 0x20);
    EXPECT_EQ(d.hardware_errors, 1u);
  }
  r.bus->read(pos);  // Get Errors cleared the register
  EXPECT_EQ(r.bus->devices()[0].health, DeviceHealth::ok);
}

TEST(MaestroBus, ASilentBoardTimesOutAndIsReportedAtBringUp) {
  Rig r;
  r.sim->set_device_responding(0, false);
  try {
    r.bus->configure();
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no answer to Get Position/Get Errors"), std::string::npos)
        << e.what();
  }
  r.sim->set_device_responding(0, true);
  r.bus->configure();
  r.sim->set_device_responding(0, false);
  std::vector<double> pos(3);
  r.bus->read(pos);
  for (const auto& d : r.bus->devices()) {
    EXPECT_EQ(d.health, DeviceHealth::timeout);
    EXPECT_EQ(d.timeouts, 1u);
  }
}

TEST(MaestroBus, PololuFormAddressesDaisyChainedBoards) {
  const std::string bus_extra = "    serial_protocol: pololu\n    device_number: 12\n";
  std::string text = robot_text(bus_extra);
  text.replace(text.find("channel: 4,"), 11, "channel: 4, device_number: 13,");
  ManualClock clock;
  RobotConfig config = load(text);
  BusConfig& b = config.buses[0];
  EXPECT_EQ(b.actuators[2].device_id, 1304);
  auto sim = std::make_unique<sim::MaestroSimBus>(b, clock);
  sim->start();
  b.port = sim->endpoint();
  auto bus = make_bus(b);
  bus->configure();
  bus->activate();
  bus->write(std::vector<double>{deg_to_rad(9), 0.0, deg_to_rad(18)});
  clock.advance(10'000'000);
  std::vector<double> pos(3);
  bus->read(pos);
  EXPECT_EQ(sim->pulse(1200), 6400);
  EXPECT_EQ(sim->pulse(1304), 6000);
  // Only board 13 stops answering: only the jaw times out.
  sim->set_device_responding(1304, false);
  bus->read(pos);
  EXPECT_EQ(bus->devices()[0].health, DeviceHealth::ok);
  EXPECT_EQ(bus->devices()[2].health, DeviceHealth::timeout);
}

TEST(MaestroBus, SerialTimeoutOfADeadHostIsClearedWithAWarningAndActivationOutlastsIt) {
  Rig r("    device_watchdog_ms: 50\n");
  ASSERT_EQ(std::any_cast<const MaestroBusOptions&>(r.config.buses[0].options).serial_timeout_ms,
            50.0);
  r.bus->configure();
  EXPECT_TRUE(dynamic_cast<MaestroBus&>(*r.bus).timeout_warning().empty());
  // A pause longer than the timeout between configure and activate (other
  // buses coming up) must not keep the board from switching on.
  r.clock.advance(200'000'000);
  ASSERT_NO_THROW(r.bus->activate());
  EXPECT_EQ(r.sim->pulse(0), 6000);
  std::vector<double> pos(3, 0.0);
  r.bus->read(pos);
  // The host dies: 50 ms of silence and the servos go limp.
  r.clock.advance(200'000'000);
  auto next = make_bus(r.config.buses[0]);
  next->configure();
  EXPECT_EQ(r.sim->pulse(0), 0);
  EXPECT_NE(dynamic_cast<MaestroBus&>(*next).timeout_warning().find(
                "serial timeout had fired on Maestro 12"),
            std::string::npos)
      << dynamic_cast<MaestroBus&>(*next).timeout_warning();
}

TEST(MaestroBus, ASerialTimeoutWhileTheOtherBusesCameUpRefusesTheRun) {
  // The board's timeout is always on: if it ran out between activate() and
  // the first cycle, the channels went home and the first target would jump
  // them back, so the run is refused, saying what to change.
  Rig r("    device_watchdog_ms: 50\n");
  r.bus->configure();
  r.bus->activate();
  r.clock.advance(20'000'000);
  ASSERT_NO_THROW(r.bus->arm_device_guard());  // within the timeout: nothing to say
  r.clock.advance(200'000'000);
  try {
    r.bus->arm_device_guard();
    FAIL() << "a serial timeout that fired before the first cycle was taken";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("serial timeout of Maestro 12 ran out while the other "
                                         "buses came up"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(r.sim->pulse(0), 0);  // switched off, not left to the board
}

// A board on a line whose answers leave on a script: the answer to burst
// k (two bytes per Get Position, then two for Get Errors) comes in the
// parts script[k] gives (a delay after the burst, a byte count); bursts
// past the script are answered at once. It drops, as a line does, only
// what has arrived.
class ScriptedBoard final : public ByteTransport {
 public:
  using Clock = std::chrono::steady_clock;
  std::map<int, std::uint16_t> pulse;   // per channel, quarter-us; 0: off
  std::map<int, std::uint16_t> target;  // the last Set Target per channel
  std::vector<std::vector<std::pair<std::chrono::microseconds, std::size_t>>> script;

  void set_timeout(std::chrono::microseconds) override {}
  bool write(std::span<const std::uint8_t> bytes) override {
    std::vector<std::uint8_t> answer;
    for (const std::uint8_t b : bytes) {
      if (parser_.feed(b) != maestro::ParseResult::command) continue;
      const maestro::Command& c = parser_.command();
      std::uint8_t two[2];
      if (c.command == maestro::cmd::get_position) {
        maestro::encode_answer(pulse[c.channel], two);
        answer.insert(answer.end(), two, two + 2);
      } else if (c.command == maestro::cmd::get_errors) {
        maestro::encode_answer(0, two);
        answer.insert(answer.end(), two, two + 2);
      } else if (c.command == maestro::cmd::set_target) {
        target[c.channel] = c.value;
      }
    }
    if (answer.empty()) return true;
    const auto now = Clock::now();
    std::size_t at = 0;
    if (bursts_ < script.size()) {
      for (const auto& [delay, count] : script[bursts_]) {
        const std::size_t n = std::min(count, answer.size() - at);
        queue_.push_back({now + delay, {answer.begin() + at, answer.begin() + at + n}});
        at += n;
      }
    }
    if (at < answer.size()) queue_.push_back({now, {answer.begin() + at, answer.end()}});
    ++bursts_;
    return true;
  }
  std::size_t read(std::span<std::uint8_t> buffer, std::chrono::microseconds wait) override {
    const auto until = Clock::now() + wait;
    std::size_t n = 0;
    for (;;) {
      while (!queue_.empty() && queue_.front().at <= Clock::now() && n < buffer.size()) {
        auto& part = queue_.front().bytes;
        const std::size_t k = std::min(part.size(), buffer.size() - n);
        std::copy(part.begin(), part.begin() + k, buffer.begin() + n);
        n += k;
        part.erase(part.begin(), part.begin() + k);
        if (part.empty()) queue_.pop_front();
      }
      if (n > 0 || Clock::now() >= until) return n;
      const auto next = queue_.empty() ? until : std::min(until, queue_.front().at);
      std::this_thread::sleep_until(next);
    }
  }
  void discard_input() override {
    const auto now = Clock::now();
    while (!queue_.empty() && queue_.front().at <= now) queue_.pop_front();
  }
  const char* failure() const override { return nullptr; }
  int failure_errno() const override { return 0; }
  std::uint64_t write_failures() const override { return 0; }
  const std::string& port() const override { return port_; }

 private:
  struct Part {
    Clock::time_point at;
    std::vector<std::uint8_t> bytes;
  };
  maestro::Parser parser_;
  std::deque<Part> queue_;
  std::size_t bursts_ = 0;
  std::string port_ = "scripted";
};

TEST(MaestroBus, AnAnswerThatCameInPartsIsNotShiftedOntoTheNextChannel) {
  // eye_pan's channel is off (reads 0), eye_tilt's at 1750 us, the jaw's at
  // 1600 us. The first burst's answer comes in part: eye_pan's two bytes at
  // once, the other six 1.5 timeouts late, during the retry, ahead of the
  // retry's own answer. Taken as the retry's, eye_tilt's 1750 us became
  // eye_pan's position, and activate switched eye_pan on at 1750 us.
  RobotConfig config = load(robot_text());
  BusConfig& b = config.buses[0];
  b.timeout_s = 0.03;
  auto owned = std::make_unique<ScriptedBoard>();
  ScriptedBoard& board = *owned;
  board.pulse = {{0, 0}, {1, 7000}, {4, 6400}};
  using std::chrono::microseconds;
  board.script = {{{microseconds(0), 2}, {microseconds(45'000), 6}}, {{microseconds(20'000), 8}}};
  MaestroBus bus(b, std::move(owned));
  bus.configure();
  bus.activate();
  // eye_pan had no position: it starts at its neutral pulse (1500 us).
  EXPECT_EQ(board.target[0], 6000);
  EXPECT_EQ(board.target[1], 7000);
  EXPECT_EQ(board.target[4], 6400);
}

}  // namespace
}  // namespace animrt
