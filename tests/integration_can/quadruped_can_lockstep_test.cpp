// The runtime against the simulated MIT motors and CiA 402 drive of
// configs/robots/quadruped_can.yaml on the in-process virtual CAN bus, on a
// lockstep clock: the whole lifecycle, tracking, determinism (no allocation
// in the cycle: tests/integration/cycle_allocation_test.cpp), and the fault
// paths: a drive that reboots mid-run, an EMCY,
// a silent drive (heartbeat consumer), an interface going bus-off, and a
// device missing at bring-up.

#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/bridge/can/mit_bus.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";

// The CAN quadruped on its simulated motors and drive in lockstep
// (support/sim_rig.hpp). `before_run` acts on the devices before bring-up.
struct Rig : test::SimRig {
  MitBus* left = nullptr;
  Cia402Bus* drive = nullptr;

  explicit Rig(const std::function<void(Rig&)>& before_run = {}) : SimRig(kRobot) {
    left = dynamic_cast<MitBus*>(&bus(0));
    drive = dynamic_cast<Cia402Bus*>(&bus(2));
    if (before_run) before_run(*this);
  }
  sim::CanSimBus& can(std::size_t i) { return dynamic_cast<sim::CanSimBus&>(*sims[i]); }
};

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(QuadrupedCanLockstep, WalksOnMitMotorsAndACia402Drive) {
  Rig rig;
  ASSERT_NE(rig.left, nullptr);
  ASSERT_NE(rig.drive, nullptr);
  const RunSummary s = rig.run(2.0);
  EXPECT_EQ(s.end_reason, EndReason::duration);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_TRUE(s.faults.empty());
  ASSERT_EQ(s.devices.size(), 12u);
  for (const auto& d : s.devices) {
    EXPECT_FALSE(d.status.faulted) << d.joint;
    EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
    EXPECT_EQ(d.status.protocol_errors, 0u) << d.joint;
    EXPECT_GE(d.status.transactions, s.cycles) << d.joint;
  }
  // First-order motors (tau 20 ms) behind a gait of at most ~140 deg/s.
  for (const auto& j : s.joints) {
    EXPECT_LT(j.max_tracking_error_rad, deg_to_rad(6.0)) << j.name;
    EXPECT_GT(j.rms_tracking_error_rad, 0.0) << j.name;
  }
  // The drive went through the state machine and back, with heartbeats.
  EXPECT_EQ(rig.drive->drive(0).state, cia402::State::switch_on_disabled);
  EXPECT_GT(rig.drive->drive(0).heartbeats, 50u);  // 20 ms producer over > 6 s
  EXPECT_EQ(rig.drive->drive(0).reboots, 0u);
  EXPECT_EQ(rig.left->transport().errors().error_frames, 0u);
  // Everything ramped home.
  for (int id : {1, 2, 3, 4, 5, 6}) EXPECT_NEAR(rig.sims[0]->device_position(id), 0.0, 0.01);
  EXPECT_NEAR(rig.sims[2]->device_position(32), 0.0, 0.01);
}

TEST(QuadrupedCanLockstep, Deterministic) {
  const std::string a = ::testing::TempDir() + "/can_a.csv";
  const std::string b = ::testing::TempDir() + "/can_b.csv";
  {
    Rig rig;
    rig.run(1.0, a);
  }
  {
    Rig rig;
    rig.run(1.0, b);
  }
  const std::string ta = read_file(a), tb = read_file(b);
  EXPECT_GT(ta.size(), 1000u);
  EXPECT_EQ(ta, tb);
}

TEST(QuadrupedCanLockstep, RebootedDriveFaultsAndTheRestRampsHome) {
  Rig rig;
  bool done = false;
  rig.probe->on_sample = [&](double t) {
    if (!done && t >= 0.5) {
      rig.can(2).reboot_device(32);
      done = true;
    }
  };
  const RunSummary s = rig.run(2.0);
  EXPECT_EQ(s.end_reason, EndReason::fault);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("bus hip_drive id 32 (rh_hip): hardware error reported"),
            std::string::npos)
      << s.faults[0];
  EXPECT_EQ(rig.drive->drive(0).reboots, 1u);
  EXPECT_NE(rig.drive->fault_text(0).find("drive rebooted"), std::string::npos);
  EXPECT_LT(s.motion_time_s, 0.6);
  for (int id : {1, 2, 3, 4, 5, 6}) EXPECT_NEAR(rig.sims[0]->device_position(id), 0.0, 0.01);
  for (int id : {7, 8, 9, 11, 12}) EXPECT_NEAR(rig.sims[1]->device_position(id), 0.0, 0.01);
}

TEST(QuadrupedCanLockstep, EmcyBecomesTheDevicesFaultReport) {
  Rig rig;
  bool done = false;
  rig.probe->on_sample = [&](double t) {
    if (!done && t >= 0.3) {
      rig.sims[2]->set_device_hardware_error(32, 0x20);  // overload
      done = true;
    }
  };
  const RunSummary s = rig.run(2.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 32 (rh_hip): hardware error reported"), std::string::npos);
  EXPECT_EQ(rig.drive->fault_text(0).substr(0, 46),
            "EMCY 0x2310 (current), error register 0x03; st");
  const auto& d = s.devices.back();
  EXPECT_EQ(d.joint, "rh_hip");
  EXPECT_EQ(d.status.hardware_error_status, 0x03);
  EXPECT_GE(d.status.hardware_errors, 1u);
}

// The drive's thread runs late (a loaded machine) while the host, which
// waits for no answer from a faulted drive, goes on: the drive still takes
// every host heartbeat at the time it was sent, so its guard does not fire
// and its own fault stays the one reported.
TEST(QuadrupedCanLockstep, ALateDriveThreadAfterItsEmcyMissesNoHostHeartbeat) {
  Rig rig;
  bool done = false;
  rig.probe->on_sample = [&](double t) {
    if (!done && t >= 0.3) {
      rig.sims[2]->set_device_hardware_error(32, 0x20);  // overload
      rig.sims[2]->set_device_answer_delay(32, 100'000'000, 3);
      done = true;
    }
  };
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 4);
  EXPECT_EQ(rig.drive->fault_text(0).substr(0, 46),
            "EMCY 0x2310 (current), error register 0x03; st");
  EXPECT_FALSE(rig.can(2).device_guard_fired(32));
  EXPECT_EQ(rig.drive->drive(0).emcy_count, 1u);
}

// The drive's answers from 0.3 s on leave later than the lockstep bus
// timeout (its thread ran late), two of them; `late_s` 0: on time.
RunSummary run_with_a_late_drive(double late_s, const std::string& csv) {
  Rig rig;
  bool delayed = false;
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.3 && !delayed && late_s > 0) {
      rig.sims[2]->set_device_answer_delay(32, from_seconds(late_s), 2);
      delayed = true;
    }
  };
  return rig.run(0.6, csv);
}

TEST(QuadrupedCanLockstep, AnAnswerLaterOnTheWallClockThanTheBusTimeoutChangesNothing) {
  const std::string on_time = ::testing::TempDir() + "/can_on_time.csv";
  const std::string late = ::testing::TempDir() + "/can_late.csv";
  const RunSummary a = run_with_a_late_drive(0.0, on_time);
  const RunSummary b = run_with_a_late_drive(kLockstepMinTimeoutS + 0.15, late);
  EXPECT_EQ(b.end_reason, EndReason::duration);
  EXPECT_EQ(test::lockstep_problems(a), "");
  EXPECT_EQ(test::lockstep_problems(b), "");
  EXPECT_EQ(a.cycles, b.cycles);
  EXPECT_EQ(test::first_difference(on_time, late), "");
}

TEST(QuadrupedCanLockstep, SilentDriveTimesOutThroughTheHeartbeatConsumer) {
  Rig rig;
  bool done = false;
  rig.probe->on_sample = [&](double t) {
    if (!done && t >= 0.3) {
      rig.sims[2]->set_device_responding(32, false);
      done = true;
    }
  };
  const RunSummary s = rig.run(2.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 32 (rh_hip): no valid answer for more than 0.1 s (last: timeout)"),
            std::string::npos)
      << s.faults[0];
  EXPECT_TRUE(rig.drive->drive(0).heartbeat_lost);
}

TEST(QuadrupedCanLockstep, BusOffFaultsEveryDeviceOnThatInterface) {
  Rig rig;
  bool done = false;
  rig.probe->on_sample = [&](double t) {
    if (!done && t >= 0.3) {
      rig.can(0).virtual_bus()->set_bus_off(true);
      done = true;
    }
  };
  const RunSummary s = rig.run(2.0);
  EXPECT_EQ(s.exit_code(), 4);
  EXPECT_EQ(s.faults.size(), 6u);
  for (const auto& line : s.faults)
    EXPECT_NE(line.find("bus legs_left"), std::string::npos) << line;
  EXPECT_EQ(rig.left->transport().errors().bus_off, 1u);
  EXPECT_TRUE(rig.left->transport().bus_off());
  EXPECT_GT(rig.left->transport().errors().tx_dropped, 0u);
  // The other interface's joints ramped home.
  for (int id : {7, 8, 9, 11, 12}) EXPECT_NEAR(rig.sims[1]->device_position(id), 0.0, 0.01);
  EXPECT_NEAR(rig.sims[2]->device_position(32), 0.0, 0.01);
  rig.can(0).virtual_bus()->set_bus_off(false);
}

// Error frames that do not stop the bus (error passive, lost arbitration)
// are counted on the interface that saw them, not on the robot's other
// interface, and named at the end of the run; the run goes on.
TEST(QuadrupedCanLockstep, ErrorFramesAreCountedPerInterfaceAndReported) {
  Rig rig;
  bool done = false;
  rig.probe->on_sample = [&](double t) {
    if (!done && t >= 0.3) {
      can_frame passive{};
      passive.can_id = CAN_ERR_CRTL;
      passive.data[1] = CAN_ERR_CRTL_TX_PASSIVE;
      rig.can(0).virtual_bus()->inject_error(passive);
      can_frame lost{};
      lost.can_id = CAN_ERR_LOSTARB;
      rig.can(0).virtual_bus()->inject_error(lost);
      done = true;
    }
  };
  ::testing::internal::CaptureStderr();
  const RunSummary s = rig.run(1.0);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_TRUE(s.faults.empty());
  EXPECT_EQ(rig.left->transport().errors().error_frames, 2u);
  EXPECT_EQ(rig.left->transport().errors().error_passive, 1u);
  EXPECT_EQ(rig.left->transport().errors().arbitration_lost, 1u);
  EXPECT_EQ(rig.drive->transport().errors().error_frames, 0u);
  EXPECT_NE(err.find("bus legs_left (virtual:can0): CAN errors: 2 error frames (1 error passive, "
                     "1 arbitration lost)"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("bus hip_drive (virtual:can1): CAN errors"), std::string::npos) << err;
}

TEST(QuadrupedCanLockstep, MissingDevicesAreNamedAtBringUp) {
  {
    Rig rig([](Rig& r) { r.sims[1]->set_device_responding(8, false); });
    try {
      rig.run(1.0);
      FAIL() << "expected DeviceError";
    } catch (const DeviceError& e) {
      EXPECT_STREQ(
          e.what(),
          "bus legs_right (virtual:can1): no answer to exit motor mode from motor id 8 (rf_knee)");
    }
  }
  {
    Rig rig([](Rig& r) { r.sims[2]->set_device_responding(32, false); });
    try {
      rig.run(1.0);
      FAIL() << "expected DeviceError";
    } catch (const DeviceError& e) {
      EXPECT_STREQ(
          e.what(),
          "bus hip_drive (virtual:can1): no answer to SDO upload 0x1000:00 (device type) from "
          "node 32 (rh_hip)");
    }
  }
}

TEST(QuadrupedCanLockstep, DriveInFaultIsResetAtActivation) {
  Rig rig([](Rig& r) {
    r.sims[2]->set_device_hardware_error(32, 0x04);
    r.sims[2]->set_device_hardware_error(32, 0);  // cause gone, drive still in fault
  });
  const RunSummary s = rig.run(0.5);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_TRUE(s.faults.empty());
}

// With `health: on` the drive's Error Code (603Fh) rides in TPDO1 with the
// statusword and position; a drive fault then ends the run naming the code.
TEST(QuadrupedCanLockstep, HealthOnCarriesTheDrivesErrorCode) {
  test::RigSettings settings;
  settings.edit = [](RobotConfig& c) {
    Cia402BusOptions o = options_of<Cia402BusOptions>(c.buses[2].options);
    o.health = true;
    c.buses[2].options = o;
  };
  test::SimRig rig(kRobot, settings);
  const int node = rig.config().buses[2].actuators[0].device_id;
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.5) rig.sims[2]->set_device_hardware_error(node, 0x04);  // overheating
  };
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_FALSE(s.faults.empty());
  EXPECT_NE(s.faults[0].find("device error bits 0x4310"), std::string::npos) << s.faults[0];
  for (const auto& d : s.devices) {
    if (d.bus == rig.config().buses[2].name) {
      EXPECT_GT(d.health.readings, 50u) << d.joint;
    }
  }
}

}  // namespace
}  // namespace animrt
