// The host's heartbeat comes from the drive bus's I/O thread, once per
// cycle: when that thread stalls longer than device_watchdog_ms, the
// simulated drive's heartbeat consumer fires even though the process lives
// on, the drive leaves Operation Enabled with EMCY 8130h, and the run
// reports it as the drive's hardware error and ramps the rest home.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "support/sim_rig.hpp"

namespace animrt::stalled_drive_thread_test {
namespace {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";

TEST(StalledDriveThread, TheDriveStopsAndTheRunSaysWhy) {
  test::RigSettings settings;
  settings.lockstep = false;  // the stall must be time that passes for the drive too
  // On the wall clock a loaded machine (the test tiers run two at a time,
  // one under the sanitizers) holds a thread up now and then: every guard
  // but the one under test is off or wide, and that one is wide enough
  // that only the stall trips it.
  settings.min_bus_timeout_s = 0.2;
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    c.safety.watchdog_timeout_s = 2.0;  // the runtime's own watchdog must not come first
    for (std::size_t leg : {0u, 1u}) {
      auto mit = options_of<MitBusOptions>(c.buses[leg].options);
      mit.device_watchdog_ms = 0;
      c.buses[leg].options = mit;
    }
    auto drive = options_of<Cia402BusOptions>(c.buses[2].options);
    drive.device_watchdog_ms = 200;
    drive.heartbeat_timeout_ms = 1000;
    c.buses[2].options = drive;
  };
  test::SimRig rig(kRobot, settings);
  std::atomic<std::uint64_t> activated_at{0};
  std::atomic<bool> active{false}, stalled{false};
  // Once, in the motion's start ramp: hold the drive bus's I/O thread 600
  // ms (three consumer times) before a read.
  rig.on_bus_call = [&](std::size_t bus, test::BusCall call, std::uint64_t index) {
    if (bus != 2 || stalled) return;
    if (call == test::BusCall::activate) {
      activated_at = rig.watched(2).calls(test::BusCall::read);
      active = true;
    }
    if (call != test::BusCall::read || !active || index < activated_at + 20) return;
    stalled = true;
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
  };
  const RunSummary s = rig.run(1.5);
  ASSERT_TRUE(stalled.load()) << "the run ended before the stall: "
                              << (s.faults.empty() ? std::string("no fault") : s.faults[0]);
  EXPECT_EQ(s.end_reason, EndReason::fault);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("bus hip_drive id 32 (rh_hip): hardware error reported"),
            std::string::npos)
      << s.faults[0];
  auto* drive = dynamic_cast<Cia402Bus*>(&rig.bus(2));
  ASSERT_NE(drive, nullptr);
  const std::string why = drive->fault_text(0);
  EXPECT_NE(why.find("EMCY 0x8130 (communication), error register 0x11"), std::string::npos) << why;
  EXPECT_NE(why.find("the drive missed the host's heartbeat for more than 200 ms "
                     "(device_watchdog_ms) and did a quick stop"),
            std::string::npos)
      << why;
}

}  // namespace
}  // namespace animrt::stalled_drive_thread_test
