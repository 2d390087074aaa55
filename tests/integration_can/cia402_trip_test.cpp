// The simulated CiA 402 drive trips by itself on overtemperature, as drive
// firmware does: above sim.health.trip_c it goes to Fault with EMCY 4310h
// (excess temperature of the drive) and its output off. A lockstep run of
// the CAN quadruped whose drive overheats ends with exit 4 naming the drive
// and its error code, with no temperature limit on the host; at the bus, a
// fault reset clears the trip only once the drive has cooled.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "support/sim_rig.hpp"

namespace animrt::cia402_trip_test {
namespace {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";
constexpr std::size_t kDrive = 2;

// The drive's error code and its temperature object in the health TPDOs;
// no temperature limit on the host: only the drive's own trip can fault.
test::RigSettings hot_drive(double trip_c) {
  test::RigSettings settings;
  settings.edit = [trip_c](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    Cia402BusOptions o = options_of<Cia402BusOptions>(c.buses[kDrive].options);
    o.health = true;
    c.buses[kDrive].options = o;
    c.buses[kDrive].health_limits = HealthLimits{};
    Cia402JointOptions j;
    j.has_temperature = true;
    j.temperature = Cia402Temperature{0x2022, 0x01, 16, true, 0.1};
    c.buses[kDrive].actuators[0].options = j;
    c.buses[kDrive].sim.health.trip_c = trip_c;
    c.buses[kDrive].sim.health.inject = {
        SimHealthInjection{32, 0.8, SimHealthInjection::Kind::temperature, 75.0}};
  };
  return settings;
}

TEST(Cia402Trip, AnOverheatedDriveTripsByItselfAndTheRunFaults) {
  test::SimRig rig(kRobot, hot_drive(70.0));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("32 (rh_hip)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("0x4310"), std::string::npos) << s.faults[0];
  for (const auto& d : s.devices) {
    if (d.joint != "rh_hip") continue;
    EXPECT_TRUE(d.status.faulted);
    EXPECT_GE(d.health.max_temperature_c, 70.0);  // the temperature it tripped at
  }
}

TEST(Cia402Trip, BelowItsTripTheDriveRunsOn) {
  test::SimRig rig(kRobot, hot_drive(90.0));
  const RunSummary s = rig.run(2.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
}

// One drive on the in-process virtual bus, the host's Cia402Bus on it.
struct Rig {
  ManualClock clock;
  std::unique_ptr<sim::CanSimBus> sim;
  std::unique_ptr<Cia402Bus> bus;

  Rig() {
    clock.set(1'000'000'000);
    BusConfig config;
    config.name = "hip";
    config.protocol = "cia402";
    config.port = "virtual:cia402_trip";
    config.timeout_s = 0.1;
    config.options = Cia402BusOptions{};
    config.sim.health.trip_c = 80.0;
    ActuatorBinding b;
    b.joint = "hip";
    b.device_id = 5;
    b.ticks_per_rad = 4096 / 6.283185307179586;
    config.actuators.push_back(b);
    sim = std::make_unique<sim::CanSimBus>(config, clock, sim::CanSimAttach::in_process);
    sim->start();
    bus = std::make_unique<Cia402Bus>(config, open_can(config.port));
  }
  ~Rig() {
    bus.reset();
    sim->stop();
  }
  void heat(double celsius) {
    sim->inject_device_health(5, {5, 0.0, SimHealthInjection::Kind::temperature, celsius});
  }
  cia402::State state() {
    return cia402::decode_statusword(
        static_cast<std::uint16_t>(bus->sdo_read(0, cia402::obj::statusword, 0)));
  }
};

TEST(Cia402Trip, AFaultResetClearsTheTripOnlyOnceCooled) {
  Rig rig;
  rig.bus->configure();
  rig.bus->activate();
  rig.heat(85.0);
  EXPECT_EQ(rig.state(), cia402::State::fault);
  EXPECT_EQ(rig.bus->sdo_read(0, cia402::obj::error_code, 0), 0x4310u);
  rig.bus->deactivate();
  // Still above the trip less 5 C: the fault reset of activate() is refused.
  rig.heat(77.0);
  rig.bus->configure();
  EXPECT_THROW(rig.bus->activate(), DeviceError);
  EXPECT_EQ(rig.state(), cia402::State::fault);
  rig.bus->deactivate();
  rig.heat(74.0);
  rig.bus->configure();
  rig.bus->activate();
  EXPECT_EQ(rig.state(), cia402::State::operation_enabled);
  EXPECT_EQ(rig.bus->sdo_read(0, cia402::obj::error_code, 0), 0u);
  rig.bus->deactivate();
}

}  // namespace
}  // namespace animrt::cia402_trip_test
