// No allocation on any thread a run owns, from the first cycle to the last:
// the loop thread and every bus's I/O thread (the telemetry writer is left
// out: it writes a file, outside the cycle by design; the ring push on the
// loop thread counts). Start ramp, motion and stop ramp, with telemetry on,
// on the fault paths, for every protocol (Dynamixel, Maestro, Modbus TCP and
// RTU, MIT and CiA 402 on CAN), in lockstep. See support/alloc_counter.hpp
// for how the run's threads are told from the simulated devices' threads.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/bridge/modbus/modbus_bus.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/modbus/modbus_sim_bus.hpp"
#include "animrt/sim/mujoco/mujoco_leg_model.hpp"
#include "support/alloc_counter.hpp"
#include "support/files.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

using test::RunAllocationWatch;
using test::RunPhase;
using test::RunThread;
using test::SimRig;

// Short ramps keep each run to about 1.5 s of simulated time.
test::RigSettings short_ramps() {
  test::RigSettings settings;
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
  };
  return settings;
}

// The animatronic figure with its torso drive on Modbus RTU (a pty).
std::string animatronic_on_rtu() {
  std::ifstream in(kConfigsDir + "/robots/animatronic.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto replace = [&](const std::string& from, const std::string& to) {
    for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  };
  replace("protocol: modbus-tcp", "protocol: modbus-rtu");
  replace("port: 192.168.1.50:502", "port: /dev/null");
  replace("    reconnect_ms: 100", "    parity: none\n    baud: 230400");
  replace("../", kConfigsDir + "/");
  const std::string path = ::testing::TempDir() + "/animatronic_rtu.yaml";
  std::ofstream(path) << text;
  return path;
}

struct Expect {
  EndReason end = EndReason::duration;
  bool telemetry = true;
  bool record = false;  // an MCAP recording beside the CSV
};

// Runs `rig` for `motion_s` under a watch; `inject(t)` runs on the loop
// thread before each sample, outside the window (a test's own call is not
// the run's allocation).
void expect_no_allocation(SimRig& rig, double motion_s, const Expect& expect,
                          const std::function<void(double)>& inject = {}) {
  RunAllocationWatch watch;
  if (inject) {
    rig.probe->on_sample = [&](double t) {
      const bool open = watch.is_open();  // closed for the sample before the first cycle
      watch.close();
      inject(t);
      if (open) watch.open();
    };
  }
  const std::string csv =
      expect.telemetry
          ? ::testing::TempDir() + "/" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".csv"
          : "";
  RunOptions options = rig.options(motion_s, csv);
  if (expect.record) {
    options.record_path = ::testing::TempDir() + "/" +
                          ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".mcap";
  }
  const RunSummary s = rig.run_watching(watch, options);
  EXPECT_EQ(s.end_reason, expect.end) << (s.faults.empty() ? "" : s.faults[0]);
  ASSERT_TRUE(watch.was_opened()) << "the window never opened: no cycle seen";
  // The window covered the whole run: every phase ran cycles.
  EXPECT_GT(rig.cycles_in(RunPhase::start_ramp), 10u);
  EXPECT_GT(rig.cycles_in(RunPhase::motion), 10u);
  EXPECT_GT(rig.cycles_in(RunPhase::stop_ramp), 10u);
  // The run's threads were seen for what they are.
  EXPECT_EQ(watch.started(RunThread::bus_io), static_cast<int>(rig.config().buses.size()));
  EXPECT_EQ(watch.started(RunThread::telemetry_writer),
            (expect.telemetry ? 1 : 0) + (expect.record ? 1 : 0));
  EXPECT_EQ(watch.started(RunThread::other), 0);
  if (expect.telemetry) {
    EXPECT_EQ(s.telemetry_records, s.cycles);
  }
  if (expect.record) {
    EXPECT_EQ(s.record_dropped, 0u);
    EXPECT_GT(s.record_messages, 2 * s.cycles);
  }
  EXPECT_EQ(watch.counted(), 0u) << "loop thread " << watch.on(RunThread::loop)
                                 << ", bus I/O threads " << watch.on(RunThread::bus_io)
                                 << "; start ramp " << watch.in(RunPhase::start_ramp) << ", motion "
                                 << watch.in(RunPhase::motion) << ", stop ramp "
                                 << watch.in(RunPhase::stop_ramp) << "\n"
                                 << watch.where();
}

// The counter itself: an allocation on a bus I/O thread or on the loop
// thread inside the window is seen, one on a thread that is not the run's
// (as the simulated devices' threads are not) is not.
TEST(CycleAllocation, TheWatchSeesTheIoThreadsAndNotTheSimulators) {
  SimRig rig(kConfigsDir + "/robots/quadruped.yaml", short_ramps());
  // A thread of the test's own, started before the watch as the simulated
  // devices' threads are, allocating all through the run.
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> outside{0};
  std::thread simulator_like([&] {
    while (!stop.load()) {
      static char* volatile p = nullptr;
      p = new char[16];
      delete[] p;
      ++outside;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  std::atomic<int> leaked{0};
  bool loop_leaked = false;
  rig.probe->on_sample = [&](double t) {
    static std::vector<int>* volatile sink = nullptr;
    if (t >= 0.2 && !loop_leaked) {
      sink = new std::vector<int>(8);  // on the loop thread, in the motion
      delete sink;
      loop_leaked = true;
    }
  };
  rig.on_bus_call = [&](std::size_t, test::BusCall call, std::uint64_t index) {
    if (call == test::BusCall::read && index == 100) {
      static char* volatile p = nullptr;
      p = new char[16];  // on the bus I/O thread, in the cycle (counted in every build)
      delete[] p;
      ++leaked;
    }
  };
  RunAllocationWatch watch;
  const std::uint64_t outside_before = outside.load();
  const RunSummary s = rig.run_watching(watch, rig.options(0.5));
  const std::uint64_t outside_during = outside.load() - outside_before;
  stop = true;
  simulator_like.join();
  EXPECT_GT(outside_during, 0u);
  EXPECT_EQ(s.end_reason, EndReason::duration);
  ASSERT_EQ(leaked.load(), 1);
  ASSERT_TRUE(loop_leaked);
  EXPECT_EQ(watch.on(RunThread::bus_io), 1u) << watch.where();
  EXPECT_EQ(watch.on(RunThread::loop), 2u) << watch.where();  // the vector and its buffer
  EXPECT_EQ(watch.in(RunPhase::motion), 3u) << watch.where();
  EXPECT_EQ(watch.counted(), 3u) << watch.where();
  EXPECT_NE(watch.where().find("bus I/O thread"), std::string::npos) << watch.where();
}

TEST(CycleAllocation, DynamixelStartMotionStopWithTelemetry) {
  SimRig rig(kConfigsDir + "/robots/quadruped.yaml", short_ramps());
  expect_no_allocation(rig, 1.0, {});
}

// The horse walking its balanced seed: each cycle the gait reads the IMU,
// poses the model's legs (forward kinematics, Jacobians) and stretches them.
TEST(CycleAllocation, BalancedGaitWithItsImu) {
  std::ifstream in(kConfigsDir + "/robots/horse.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("../gaits/horse_walk.yaml", kConfigsDir + "/gaits/horse_seed_balance.yaml");
  replace("../models/horse.xml", kConfigsDir + "/models/horse.xml");
  text += "imus:\n  - {name: trunk, protocol: bno08x_rvc, stale_timeout_s: 0.5}\n";
  const std::string path = ::testing::TempDir() + "/horse_balanced.yaml";
  std::ofstream(path) << text;
  test::RigSettings settings = short_ramps();
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    // Servos as quick as the walk: no following-error fault without physics.
    for (BusConfig& bus : c.buses) bus.sim.max_speed_rad_s = 100.0;
  };
  BalancedGaitSource* balanced = nullptr;
  settings.edit_motion = [&balanced](LoadedRobot& robot) {
    ASSERT_NE(robot.balanced, nullptr);
    balanced = robot.balanced;
    std::vector<std::string> names;
    for (const JointSpec& joint : robot.config.joints) names.push_back(joint.name);
    robot.balanced->attach(
        std::make_unique<sim::MujocoLegModel>(robot.config.model, names, robot.config.model_where));
  };
  SimRig rig(path, settings);
  expect_no_allocation(rig, 1.0, {});
  // The reflex ran: the IMU's readings reached it (100 Hz over 1 s of motion).
  ASSERT_NE(balanced, nullptr);
  EXPECT_GT(balanced->readings(), 50u);
}

TEST(CycleAllocation, DynamixelDeviceDyingMidRun) {
  SimRig rig(kConfigsDir + "/robots/quadruped.yaml", short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("legs").set_device_responding(5, false);
    done = done || t >= 0.3;
  });
}

TEST(CycleAllocation, DynamixelHardwareError) {
  SimRig rig(kConfigsDir + "/robots/quadruped.yaml", short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("legs").set_device_hardware_error(9, 0x04);
    done = done || t >= 0.3;
  });
}

// Health read with the positions (and one servo per cycle), a warning on
// the way and a health fault (switching a servo off) at the end.
test::RigSettings health_on(dxl::HealthRead how) {
  test::RigSettings settings = short_ramps();
  settings.edit = [how](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    c.safety.health.temperature_warn_c = 50;
    c.safety.health.temperature_fault_c = 70;
    dxl::BusOptions o = dxl::bus_options(c.buses[0]);
    o.health = how;
    c.buses[0].options = o;
  };
  return settings;
}

TEST(CycleAllocation, DynamixelHealthPackedWarningAndFault) {
  SimRig rig(kConfigsDir + "/robots/quadruped.yaml", health_on(dxl::HealthRead::packed));
  int step = 0;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    using Kind = SimHealthInjection::Kind;
    if (step == 0 && t >= 0.2) {
      rig.sim("legs").inject_device_health(4, {4, 0, Kind::temperature, 55});
      ++step;
    } else if (step == 1 && t >= 0.4) {
      rig.sim("legs").inject_device_health(9, {9, 0, Kind::temperature, 75});
      ++step;
    }
  });
}

TEST(CycleAllocation, DynamixelHealthRoundRobin) {
  SimRig rig(kConfigsDir + "/robots/quadruped.yaml", health_on(dxl::HealthRead::round_robin));
  expect_no_allocation(rig, 1.0, {});
}

// The MCAP recording's pushes (joints, loop, device status, the fault's
// event and the stop ramp) on the loop thread.
TEST(CycleAllocation, DynamixelHardwareErrorRecorded) {
  SimRig rig(kConfigsDir + "/robots/quadruped.yaml", short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault, true, true}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("legs").set_device_hardware_error(9, 0x04);
    done = done || t >= 0.3;
  });
}

TEST(CycleAllocation, DynamixelMaestroModbusTcpWithTelemetry) {
  SimRig rig(kConfigsDir + "/robots/animatronic.yaml", short_ramps());
  expect_no_allocation(rig, 1.0, {});
}

TEST(CycleAllocation, MaestroErrorBits) {
  SimRig rig(kConfigsDir + "/robots/animatronic.yaml", short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("face").set_device_hardware_error(0, 0x10);
    done = done || t >= 0.3;
  });
}

// The TCP connection drops: the bus reconnects with backoff inside the
// cycle until the watchdog faults the drive.
TEST(CycleAllocation, ModbusTcpDroppedConnection) {
  SimRig rig(kConfigsDir + "/robots/animatronic.yaml", short_ramps());
  auto& torso = dynamic_cast<sim::ModbusSimBus&>(rig.sim("torso"));
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) {
      torso.stop();
      torso.drop_connections();
    }
    done = done || t >= 0.3;
  });
}

// Health read apart (round robin) and recorded; a fault code switches the
// drive off from inside the cycle.
TEST(CycleAllocation, ModbusTcpHealthAndAFaultCode) {
  test::RigSettings settings = short_ramps();
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    auto o = std::any_cast<ModbusBusOptions>(c.buses[2].options);
    o.health = ModbusBusOptions::Health::round_robin;
    c.buses[2].options = o;
  };
  SimRig rig(kConfigsDir + "/robots/animatronic.yaml", settings);
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault, true, true}, [&](double t) {
    if (!done && t >= 0.3)
      rig.sim("torso").inject_device_health(
          1, SimHealthInjection{1, 0.0, SimHealthInjection::Kind::hardware_error, 0x21});
    done = done || t >= 0.3;
  });
}

TEST(CycleAllocation, ModbusRtuWithTelemetry) {
  SimRig rig(animatronic_on_rtu(), short_ramps());
  ASSERT_EQ(rig.config().buses[2].protocol, "modbus-rtu");
  expect_no_allocation(rig, 1.0, {});
}

TEST(CycleAllocation, ModbusRtuSilentDrive) {
  SimRig rig(animatronic_on_rtu(), short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("torso").set_device_responding(1, false);
    done = done || t >= 0.3;
  });
}

TEST(CycleAllocation, ModbusRtuDriveFaultBits) {
  SimRig rig(animatronic_on_rtu(), short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("torso").set_device_hardware_error(1, 0x01);
    done = done || t >= 0.3;
  });
}

TEST(CycleAllocation, MitAndCia402WithTelemetry) {
  SimRig rig(kConfigsDir + "/robots/quadruped_can.yaml", short_ramps());
  expect_no_allocation(rig, 1.0, {});
}

TEST(CycleAllocation, Cia402Emcy) {
  SimRig rig(kConfigsDir + "/robots/quadruped_can.yaml", short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("hip_drive").set_device_hardware_error(32, 0x20);
    done = done || t >= 0.3;
  });
}

TEST(CycleAllocation, MitSilentMotor) {
  SimRig rig(kConfigsDir + "/robots/quadruped_can.yaml", short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) rig.sim("legs_left").set_device_responding(2, false);
    done = done || t >= 0.3;
  });
}

TEST(CycleAllocation, CanBusOff) {
  SimRig rig(kConfigsDir + "/robots/quadruped_can.yaml", short_ramps());
  auto& left = dynamic_cast<sim::CanSimBus&>(rig.sim("legs_left"));
  bool done = false;
  expect_no_allocation(rig, 2.0, {EndReason::fault}, [&](double t) {
    if (!done && t >= 0.3) left.virtual_bus()->set_bus_off(true);
    done = done || t >= 0.3;
  });
  left.virtual_bus()->set_bus_off(false);
}

}  // namespace
}  // namespace animrt
