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

#include "animrt/bridge/can/cia402_bus.hpp"
#include "support/sim_rig.hpp"

namespace animrt::stalled_drive_thread_test {
namespace {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";

TEST(StalledDriveThread, TheDriveStopsAndTheRunSaysWhy) {
  test::RigSettings settings;
  settings.lockstep = false;  // the stall must be time that passes for the drive too
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    c.safety.watchdog_timeout_s = 0.5;  // the runtime's own watchdog must not come first
  };
  test::SimRig rig(kRobot, settings);
  std::atomic<bool> active{false}, stalled{false};
  // Once, in the middle of the motion: hold the drive bus's I/O thread 150
  // ms (three consumer times) before a read.
  rig.on_bus_call = [&](std::size_t bus, test::BusCall call, std::uint64_t index) {
    if (call == test::BusCall::activate) active = true;
    if (bus != 2 || call != test::BusCall::read || !active || index < 100 || stalled) return;
    stalled = true;
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
  };
  const RunSummary s = rig.run(1.0);
  ASSERT_TRUE(stalled.load());
  EXPECT_EQ(s.end_reason, EndReason::fault);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("bus hip_drive id 32 (rh_hip): hardware error reported"),
            std::string::npos)
      << s.faults[0];
  auto* drive = dynamic_cast<Cia402Bus*>(&rig.bus(2));
  ASSERT_NE(drive, nullptr);
  const std::string why = drive->fault_text(0);
  EXPECT_NE(why.find("EMCY 0x8130 (communication), error register 0x11"), std::string::npos) << why;
  EXPECT_NE(why.find("the drive missed the host's heartbeat for more than 50 ms "
                     "(device_watchdog_ms) and did a quick stop"),
            std::string::npos)
      << why;
}

}  // namespace
}  // namespace animrt::stalled_drive_thread_test
