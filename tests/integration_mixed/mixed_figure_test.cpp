// The animatronic figure (Dynamixel neck, Maestro jaw and eyes, Modbus TCP
// torso) against simulated devices on their real wire protocols: the show on
// all three buses in lockstep, a slow bus, a dead bus beside live ones, and
// the fault paths of the new buses (a dropped TCP connection, drive fault
// bits, Maestro error bits). Every run is in lockstep: behaviour, not timing.

#include <gtest/gtest.h>

#include <algorithm>
#include <any>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/bridge/modbus/modbus_bus.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/sim/modbus/modbus_sim_bus.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

const std::string kFigure = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml";

// The figure on its simulated devices (support/sim_rig.hpp), in lockstep
// unless asked otherwise. The torso drive may answer `torso_delay_us` late.
struct Rig : test::SimRig {
  explicit Rig(bool lockstep_run = true, int torso_delay_us = 0, double torso_timeout_s = 0.2,
               double ramp_s = 0.0, double watchdog_s = 0.0)
      : SimRig(kFigure,
               settings(lockstep_run, torso_delay_us, torso_timeout_s, ramp_s, watchdog_s)) {}

  static test::RigSettings settings(bool lockstep, int torso_delay_us, double torso_timeout_s,
                                    double ramp_s, double watchdog_s) {
    test::RigSettings s;
    s.lockstep = lockstep;
    s.min_bus_timeout_s = 0.25;  // a loaded machine (ASan, CI) must not time out
    s.edit = [=](RobotConfig& c) {
      if (ramp_s > 0) c.safety.start_ramp_s = c.safety.stop_ramp_s = ramp_s;
      if (watchdog_s > 0) c.safety.watchdog_timeout_s = watchdog_s;
      for (auto& bus : c.buses) {
        if (bus.name != "torso") continue;
        bus.sim.return_delay_us = torso_delay_us;
        bus.timeout_s = torso_timeout_s;
        // Longer than any watchdog in these runs: a drop is not healed in time.
        std::any_cast<ModbusBusOptions&>(bus.options).reconnect_min_s = 5.0;
      }
    };
    return s;
  }
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const DeviceReport& device(const RunSummary& s, const std::string& joint) {
  for (const auto& d : s.devices) {
    if (d.joint == joint) return d;
  }
  throw std::out_of_range(joint);
}

TEST(MixedFigure, TheShowRunsOnAllThreeBusesInLockstep) {
  Rig rig;
  std::vector<double> jaw, torso;
  const std::string csv = ::testing::TempDir() + "/mixed.csv";
  RunSummary s = rig.run(3.0, csv);
  EXPECT_EQ(s.end_reason, EndReason::duration);
  EXPECT_TRUE(s.faults.empty());
  ASSERT_EQ(s.devices.size(), 6u);
  for (const auto& d : s.devices) {
    EXPECT_FALSE(d.status.faulted) << d.joint;
    EXPECT_EQ(
        d.status.timeouts + d.status.crc_errors + d.status.protocol_errors + d.status.exceptions,
        0u)
        << d.joint;
    EXPECT_GE(d.status.transactions, s.cycles) << d.joint;
  }
  EXPECT_TRUE(device(s, "jaw").status.open_loop);
  EXPECT_FALSE(device(s, "torso_lean").status.open_loop);
  ASSERT_EQ(s.buses.size(), 3u);
  for (const auto& j : s.joints) EXPECT_LT(j.max_tracking_error_rad, deg_to_rad(2.0)) << j.name;
  // The show moved the jaw (0..20 deg) and the figure ended at home.
  const std::string text = slurp(csv);
  EXPECT_GT(std::count(text.begin(), text.end(), '\n'), 300);
  EXPECT_NEAR(rig.sim("face").device_position(0), 0.0, deg_to_rad(0.1));
  EXPECT_NEAR(rig.sim("torso").device_position(1), 0.0, deg_to_rad(0.5));
}

// The figure does not walk (its neck sway is a gait that says so): a stop
// has nothing to wind down and ramps home at once; the motion is not
// played past the request.
TEST(MixedFigure, AStopRampsHomeAtOnceWithNothingToWindDown) {
  EXPECT_EQ(load_robot(kFigure).motion->wind_down(1.0, 100.0), 0.0);
  Rig rig(true, 0, 0.2, 0.3);
  double last = -1.0;
  rig.probe->on_sample = [&](double t) { last = std::max(last, t); };
  RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.end_reason, EndReason::duration);
  EXPECT_TRUE(s.faults.empty());
  EXPECT_GT(last, 0.9);
  EXPECT_LT(last, 1.0);
}

TEST(MixedFigure, ASlowBusChangesNothingInLockstep) {
  const std::string fast = ::testing::TempDir() + "/mixed_fast.csv";
  const std::string slow = ::testing::TempDir() + "/mixed_slow.csv";
  RunSummary a, b;
  {
    Rig rig(true, 0, 0.2, 0.3);
    a = rig.run(0.5, fast);
  }
  {
    Rig rig(true, 12000, 0.2,
            0.3);  // the drive takes 12 ms to answer, longer than the 10 ms period
    b = rig.run(0.5, slow);
  }
  EXPECT_EQ(a.cycles, b.cycles);
  for (const auto& d : b.devices) EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
  EXPECT_EQ(slurp(fast), slurp(slow));
}

TEST(MixedFigure, ADroppedModbusConnectionFaultsTheTorsoAfterTheWatchdog) {
  Rig rig;
  auto& torso = dynamic_cast<sim::ModbusSimBus&>(rig.sim("torso"));
  bool dropped = false;
  rig.probe->on_sample = [&](double t) {
    if (t >= 1.0 && !dropped) {
      torso.stop();  // connections gone, nobody listening on the accept queue
      torso.drop_connections();
      dropped = true;
    }
  };
  RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.end_reason, EndReason::fault);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("torso_lean"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("no valid answer for more than 0.1 s"), std::string::npos)
      << s.faults[0];
  EXPECT_LT(s.motion_time_s, 1.2);
  for (const auto& d : s.devices) {
    EXPECT_EQ(d.status.faulted, d.joint == "torso_lean") << d.joint;
    if (d.joint != "torso_lean") {
      EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
    }
  }
  EXPECT_EQ(s.exit_code(), 4);
}

TEST(MixedFigure, DriveFaultBitsFaultTheTorsoAtOnce) {
  Rig rig;
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.5) rig.sim("torso").set_device_hardware_error(1, 0x01);  // motor overload
  };
  RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.end_reason, EndReason::fault);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("torso_lean"), std::string::npos);
  EXPECT_NE(s.faults[0].find("hardware error"), std::string::npos);
  EXPECT_LT(s.motion_time_s, 0.52);
  EXPECT_EQ(device(s, "torso_lean").status.hardware_error_status, 0x01);
}

TEST(MixedFigure, MaestroErrorBitsFaultTheFace) {
  Rig rig;
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.5) rig.sim("face").set_device_hardware_error(0, 0x10);  // serial protocol error
  };
  RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.end_reason, EndReason::fault);
  EXPECT_EQ(s.faults.size(), 3u);  // one board: jaw and both eyes
  for (const auto& name : {"jaw", "eye_pan", "eye_tilt"}) {
    EXPECT_TRUE(device(s, name).status.faulted) << name;
    EXPECT_EQ(device(s, name).status.hardware_error_status, 0x10) << name;
  }
  EXPECT_FALSE(device(s, "neck_pan").status.faulted);
  EXPECT_FALSE(device(s, "torso_lean").status.faulted);
}

// Telemetry as rows of numbers under its header's column names.
struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<std::string>> rows;
  std::size_t column(const std::string& name) const {
    for (std::size_t c = 0; c < names.size(); ++c) {
      if (names[c] == name) return c;
    }
    throw std::out_of_range(name);
  }
};

Table read_csv(const std::string& path) {
  Table table;
  std::istringstream text(slurp(path));
  std::string line;
  bool header = true;
  while (std::getline(text, line)) {
    std::vector<std::string> cells;
    std::istringstream fields(line);
    std::string cell;
    while (std::getline(fields, cell, ',')) cells.push_back(cell);
    if (header) {
      table.names = cells;
      header = false;
    } else {
      table.rows.push_back(cells);
    }
  }
  return table;
}

// One dead bus in lockstep: the torso's drive goes silent (its server and
// connections are gone) after 0.5 s of motion, and the watchdog is longer
// than the run so the run goes on without it. The other buses are still read
// and written every cycle, and their joints move exactly as they do beside a
// healthy torso: every other column of the telemetry is identical, cycle for
// cycle. The silent drive is counted as timing out on every cycle after.
TEST(MixedFigure, ADeadBusDoesNotStallTheOthers) {
  const std::string healthy_csv = ::testing::TempDir() + "/mixed_healthy.csv";
  const std::string dead_csv = ::testing::TempDir() + "/mixed_dead.csv";
  constexpr double kDrop = 0.5;
  RunSummary a, b;
  {
    Rig rig(true, 0, 0.2, 0.3, 100.0);
    a = rig.run(1.5, healthy_csv);
  }
  std::uint64_t samples_after_drop = 0;
  {
    Rig rig(true, 0, 0.2, 0.3, 100.0);
    auto& torso = dynamic_cast<sim::ModbusSimBus&>(rig.sim("torso"));
    bool dropped = false;
    rig.probe->on_sample = [&](double t) {
      if (dropped) ++samples_after_drop;
      if (t >= kDrop && !dropped) {
        torso.stop();
        torso.drop_connections();
        dropped = true;
      }
    };
    b = rig.run(1.5, dead_csv);
  }
  EXPECT_EQ(b.end_reason, EndReason::duration);
  EXPECT_TRUE(b.faults.empty());
  EXPECT_EQ(a.cycles, b.cycles);
  ASSERT_GT(samples_after_drop, 90u);  // 1 s of motion at 100 Hz

  for (const std::string joint : {"neck_pan", "neck_tilt", "jaw", "eye_pan", "eye_tilt"}) {
    const DeviceStatus& st = device(b, joint).status;
    EXPECT_EQ(st.transactions, device(a, joint).status.transactions) << joint;
    EXPECT_GE(st.transactions, b.cycles) << joint;
    EXPECT_EQ(st.timeouts + st.crc_errors + st.protocol_errors + st.exceptions, 0u) << joint;
    EXPECT_FALSE(st.faulted) << joint;
  }
  for (const auto& j : b.joints) {
    if (j.name != "torso_lean") {
      EXPECT_LT(j.max_tracking_error_rad, deg_to_rad(2.0)) << j.name;
    }
  }
  const DeviceStatus& torso = device(b, "torso_lean").status;
  EXPECT_FALSE(torso.faulted);
  EXPECT_GE(torso.timeouts, samples_after_drop);
  EXPECT_EQ(device(a, "torso_lean").status.timeouts, 0u);

  const Table healthy = read_csv(healthy_csv), dead = read_csv(dead_csv);
  ASSERT_EQ(healthy.names, dead.names);
  ASSERT_EQ(healthy.rows.size(), dead.rows.size());
  ASSERT_EQ(dead.rows.size(), b.cycles);
  const std::size_t torso_measured = dead.column("torso_lean_meas_rad");
  std::size_t torso_differs = 0;
  for (std::size_t r = 0; r < dead.rows.size(); ++r) {
    for (std::size_t c = 0; c < dead.names.size(); ++c) {
      if (c == torso_measured) {
        torso_differs += healthy.rows[r][c] != dead.rows[r][c];
      } else {
        ASSERT_EQ(healthy.rows[r][c], dead.rows[r][c]) << dead.names[c] << " at row " << r;
      }
    }
  }
  // The dead torso's measurement froze while the healthy one moved on.
  EXPECT_GT(torso_differs, samples_after_drop / 2);
}

}  // namespace
}  // namespace animrt
