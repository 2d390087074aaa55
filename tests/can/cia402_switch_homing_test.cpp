// Homing a CiA 402 drive on its switches (methods 17-30) through
// Cia402Bus::set_home, against the simulated drive on the in-process virtual
// bus, its clock advanced by the test (a simulated clock): the method, its
// speeds and acceleration are written by SDO, the drive moves toward the
// switch (its position actual in the TPDOs walks there), stops at the edge,
// which then reads the home offset; a limit switch the method does not use
// is a homing error, and the drive ends disabled either way. HomingSearch
// alone: each family of methods finds the edge it should, turning round at
// the limit switch its method uses.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/can/homing_search.hpp"

namespace animrt::cia402_switch_homing_test {
namespace {

constexpr Nanos kMs = 1'000'000;
constexpr canid_t kNode = 22;
constexpr std::int32_t kHome = 5'000;
constexpr double kCountsPerRev = 36'000.0;  // 100 counts per degree
constexpr double kCountsPerDeg = kCountsPerRev / 360.0;

struct Rig {
  ManualClock clock;
  BusConfig config;
  std::unique_ptr<sim::CanSimBus> sim;
  std::unique_ptr<CanFrameTransport> sniffer;
  std::unique_ptr<Cia402Bus> bus;
  std::atomic<bool> pacing{false};
  std::thread pacer;

  Rig(const std::string& name, int method, const SimDriveSwitches& switches) {
    clock.set(1000 * kMs);
    config.name = "slide";
    config.protocol = "cia402";
    config.port = "virtual:" + name;
    config.timeout_s = 0.5;
    config.options = Cia402BusOptions{};
    ActuatorBinding b;
    b.joint = "slide";
    b.device_id = kNode;
    b.ticks_per_rad = kCountsPerRev / 6.283185307179586;
    Cia402JointOptions o;
    o.homing.method = static_cast<std::int8_t>(method);
    o.homing.switch_speed = static_cast<std::uint32_t>(180 * kCountsPerDeg);
    o.homing.zero_speed = static_cast<std::uint32_t>(45 * kCountsPerDeg);
    o.homing.acceleration = static_cast<std::uint32_t>(1000 * kCountsPerDeg);
    o.homing.timeout_s = 20.0;
    b.options = o;
    config.actuators.push_back(b);
    BusConfig drive_side = config;
    drive_side.sim.switches.push_back(switches);
    drive_side.sim.switches.back().device_id = kNode;
    sim = std::make_unique<sim::CanSimBus>(drive_side, clock, sim::CanSimAttach::in_process);
    sim->start();
    sniffer = VirtualCanBus::named(name)->attach();
    bus = std::make_unique<Cia402Bus>(config, open_can(config.port));
    bus->configure();
    bus->deactivate();
  }
  ~Rig() {
    stop_pacing();
    bus.reset();
    sim->stop();
  }
  // The simulated clock runs at about twice the wall clock while homing.
  void start_pacing() {
    pacing = true;
    pacer = std::thread([this] {
      while (pacing.load()) {
        clock.advance(kMs);
        std::this_thread::sleep_for(std::chrono::microseconds(500));
      }
    });
  }
  void stop_pacing() {
    pacing = false;
    if (pacer.joinable()) pacer.join();
  }
  std::int64_t home() {
    start_pacing();
    struct Stop {
      Rig& r;
      ~Stop() { r.stop_pacing(); }
    } stop{*this};
    return bus->set_home(0, kHome);
  }
  // Positions (deg) the drive's TPDO1 reported, in order; and the SDO
  // downloads seen (index << 8 | sub, value).
  std::vector<double> tpdo_deg;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> downloads;
  void drain() {
    can_frame f;
    while (sniffer->receive(f, std::chrono::milliseconds(20))) {
      if (f.can_id == canopen::kTpdo1Base + kNode && f.len >= 6) {
        const auto counts = static_cast<std::int32_t>(canopen::get_le(f.data + 2, 4));
        tpdo_deg.push_back(counts / kCountsPerDeg);
      }
      if (f.can_id == canopen::kRsdoBase + kNode && (f.data[0] & 0xE0) == 0x20) {
        downloads.emplace_back(canopen::get_le(f.data + 1, 2) << 8 | f.data[3],
                               canopen::get_le(f.data + 4, 4));
      }
    }
  }
  bool downloaded(std::uint16_t index, std::uint8_t sub, std::uint32_t value) const {
    for (const auto& [key, v] : downloads) {
      if (key == (static_cast<std::uint32_t>(index) << 8 | sub) && v == value) return true;
    }
    return false;
  }
  std::int32_t position() {
    return static_cast<std::int32_t>(bus->sdo_read(0, cia402::obj::position_actual, 0));
  }
  void expect_disabled_in_csp() {
    EXPECT_EQ(bus->sdo_read(0, cia402::obj::modes_of_operation, 0),
              static_cast<std::uint32_t>(cia402::kModeCsp));
    const auto sw = static_cast<std::uint16_t>(bus->sdo_read(0, cia402::obj::statusword, 0));
    EXPECT_EQ(cia402::decode_statusword(sw), cia402::State::switch_on_disabled);
  }
};

SimDriveSwitches home_switch_from(double deg) {
  SimDriveSwitches s;
  s.has_home = true;
  s.home_from_deg = deg;
  return s;
}

TEST(Cia402SwitchHoming, Method19MovesToThePositiveHomeSwitchAndHomesAtItsEdge) {
  Rig rig("switch_home_19", 19, home_switch_from(40.0));
  const std::int32_t start = rig.position();
  ASSERT_LT(std::abs(start), 20 * kCountsPerDeg);  // powers up near 0, off the switch
  rig.drain();
  EXPECT_EQ(rig.home(), kHome);
  rig.drain();
  // The method, its speeds (counts/s) and acceleration went to the drive.
  EXPECT_TRUE(rig.downloaded(cia402::obj::homing_method, 0, 19));
  EXPECT_TRUE(rig.downloaded(cia402::obj::homing_speeds, 1, 18'000));
  EXPECT_TRUE(rig.downloaded(cia402::obj::homing_speeds, 2, 4'500));
  EXPECT_TRUE(rig.downloaded(cia402::obj::homing_accel, 0, 100'000));
  // It moved: its position actual walked up toward the switch at 40 deg,
  // never past it, until the edge read the home offset.
  ASSERT_GE(rig.tpdo_deg.size(), 3u);
  double furthest = -1e9;
  for (double deg : rig.tpdo_deg) {
    if (deg == kHome / kCountsPerDeg) break;
    EXPECT_GE(deg, furthest);
    furthest = deg;
  }
  EXPECT_GT(furthest, 30.0);
  EXPECT_LE(furthest, 40.0);
  // Stopped there, at rest: it reads the home and goes on reading it.
  EXPECT_EQ(rig.position(), kHome);
  rig.clock.advance(2000 * kMs);
  EXPECT_EQ(rig.position(), kHome);
  rig.expect_disabled_in_csp();
}

TEST(Cia402SwitchHoming, Method17HomesOnTheNegativeLimitSwitch) {
  SimDriveSwitches s;
  s.negative_limit_deg = -60.0;
  s.positive_limit_deg = 60.0;
  Rig rig("switch_home_17", 17, s);
  rig.drain();
  EXPECT_EQ(rig.home(), kHome);
  rig.drain();
  double lowest = 1e9;
  for (double deg : rig.tpdo_deg) {
    if (deg == kHome / kCountsPerDeg) break;
    lowest = std::min(lowest, deg);
  }
  EXPECT_LT(lowest, -50.0);
  EXPECT_GE(lowest, -60.0);
  EXPECT_EQ(rig.position(), kHome);
  rig.expect_disabled_in_csp();
}

TEST(Cia402SwitchHoming, ALimitSwitchTheMethodDoesNotUseIsAHomingError) {
  // Method 19 searches upward for a home switch beyond the positive limit.
  SimDriveSwitches s = home_switch_from(90.0);
  s.positive_limit_deg = 30.0;
  Rig rig("switch_home_error", 19, s);
  try {
    rig.home();
    FAIL() << "homed past a limit switch";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("homing error"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("slide"), std::string::npos) << e.what();
  }
  // Stopped at the limit switch, not homed (no offset taken), disabled.
  EXPECT_NEAR(rig.position() / kCountsPerDeg, 30.0, 0.01);
  rig.expect_disabled_in_csp();
}

TEST(Cia402SwitchHoming, ASwitchNeverFoundEndsAtTheTimeoutHalted) {
  // No switch at all: the host gives up after timeout_s and halts the search.
  Rig rig("switch_home_none", 18, SimDriveSwitches{});
  auto o = options_of<Cia402JointOptions>(rig.config.actuators[0].options);
  o.homing.timeout_s = 0.3;
  rig.config.actuators[0].options = o;
  rig.bus = std::make_unique<Cia402Bus>(rig.config, open_can(rig.config.port));
  rig.bus->configure();
  rig.bus->deactivate();
  EXPECT_THROW(rig.home(), DeviceError);
  const std::int32_t stopped = rig.position();
  rig.clock.advance(1000 * kMs);
  EXPECT_EQ(rig.position(), stopped);  // halted: no longer moving
  rig.expect_disabled_in_csp();
}

// ---- the search alone --------------------------------------------------------

constexpr double kInf = std::numeric_limits<double>::infinity();

// Runs a search from `start` at 100 counts/s (25 after turning round) for
// up to 100 s; where it ended and how.
std::pair<sim::HomingSearch::Phase, double> search(int method, sim::HomingSearch::Switches sw,
                                                   double start) {
  sim::HomingSearch s(method, sw, start, 100.0, 25.0, 0);
  for (Nanos t = 0; t <= 100'000 * kMs && s.phase() == sim::HomingSearch::Phase::searching;
       t += 7 * kMs) {
    s.advance(t);
  }
  return {s.phase(), s.position()};
}

TEST(HomingSearch, EachMethodFindsItsEdge) {
  using P = sim::HomingSearch::Phase;
  const sim::HomingSearch::Switches cam{100.0, 200.0, -1000.0, 1000.0};
  // 23-26 search upward first; from beyond the cam the positive limit turns
  // them round. 23/24 home on the cam's lower edge, 25/26 its upper.
  EXPECT_EQ(search(23, cam, 0.0), std::make_pair(P::attained, 100.0));
  EXPECT_EQ(search(23, cam, 500.0), std::make_pair(P::attained, 100.0));
  EXPECT_EQ(search(26, cam, 500.0), std::make_pair(P::attained, 200.0));
  EXPECT_EQ(search(25, cam, 150.0), std::make_pair(P::attained, 200.0));
  // 27-30 search downward first, turned round by the negative limit.
  EXPECT_EQ(search(27, cam, 0.0), std::make_pair(P::attained, 200.0));
  EXPECT_EQ(search(29, cam, 0.0), std::make_pair(P::attained, 100.0));
  EXPECT_EQ(search(30, cam, 150.0), std::make_pair(P::attained, 100.0));
  // A negative home switch (active below its edge), from either side.
  const sim::HomingSearch::Switches negative{-kInf, -300.0, -kInf, kInf};
  EXPECT_EQ(search(21, negative, 0.0), std::make_pair(P::attained, -300.0));
  EXPECT_EQ(search(22, negative, -700.0), std::make_pair(P::attained, -300.0));
  // 18 from on its limit switch: off it, and the edge is the home.
  const sim::HomingSearch::Switches limits{kInf, -kInf, -400.0, 400.0};
  EXPECT_EQ(search(18, limits, 450.0), std::make_pair(P::attained, 400.0));
  // Errors: 23 turned round once and met the other limit (no home switch);
  // 21 meets a limit it does not use.
  EXPECT_EQ(search(23, limits, 0.0), std::make_pair(P::error, -400.0));
  EXPECT_EQ(search(21, limits, 0.0), std::make_pair(P::error, -400.0));
}

}  // namespace
}  // namespace animrt::cia402_switch_homing_test
