// The runtime against simulated Dynamixel servos over a real pseudo-terminal,
// on a lockstep clock: the whole lifecycle, tracking, determinism, and the
// fault path when a device dies or reports a hardware error. (No allocation
// in the cycle: cycle_allocation_test.cpp, on every thread of the run.)

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

const std::string kQuadruped = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";

// The quadruped on its simulated servos in lockstep (support/sim_rig.hpp);
// wire time off, so the run does not depend on the machine's speed.
struct Rig : test::SimRig {
  Rig() : SimRig(kQuadruped) {}
};

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
};

Csv read_csv(const std::string& path) {
  Csv csv;
  std::ifstream in(path);
  std::string line, cell;
  std::getline(in, line);
  std::stringstream hs(line);
  while (std::getline(hs, cell, ',')) csv.header.push_back(cell);
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::vector<double> row;
    while (std::getline(ls, cell, ',')) row.push_back(std::stod(cell));
    csv.rows.push_back(row);
  }
  return csv;
}

TEST(QuadrupedLockstep, WalksTheGaitAndTracksWithinTheServoModel) {
  Rig rig;
  const std::string csv_path = ::testing::TempDir() + "/lockstep_walk.csv";
  RunSummary s = rig.run(3.0, csv_path);

  EXPECT_EQ(s.end_reason, EndReason::duration);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_TRUE(s.faults.empty());
  EXPECT_NEAR(s.motion_time_s, 3.0, 0.006);
  ASSERT_EQ(s.devices.size(), 12u);
  for (const auto& d : s.devices) {
    EXPECT_FALSE(d.status.faulted) << d.joint;
    EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
    EXPECT_EQ(d.status.crc_errors, 0u) << d.joint;
    EXPECT_EQ(d.status.protocol_errors, 0u) << d.joint;
    EXPECT_GE(d.status.transactions, s.cycles) << d.joint;
  }
  EXPECT_EQ(s.telemetry_dropped, 0u);
  EXPECT_EQ(s.telemetry_records, s.cycles);

  // A first-order servo with time constant tau lags a command moving at v by
  // about tau*v, so the RMS error is bounded by tau * RMS(v) plus a margin for
  // the one-cycle delay and the tick quantisation.
  const double tau = rig.config().buses[0].sim.time_constant_s;
  const double dt = 1.0 / rig.config().rate_hz;
  const double tick = 2 * M_PI / 4096;
  Csv csv = read_csv(csv_path);
  ASSERT_EQ(csv.rows.size(), s.cycles);
  for (std::size_t j = 0; j < s.joints.size(); ++j) {
    const auto& name = s.joints[j].name;
    const int cmd = csv.column(name + "_cmd_rad");
    double sum_v2 = 0.0;
    double moved = 0.0;
    for (std::size_t k = 1; k < csv.rows.size(); ++k) {
      const double v = (csv.rows[k][cmd] - csv.rows[k - 1][cmd]) / dt;
      sum_v2 += v * v;
      moved = std::max(moved, std::abs(csv.rows[k][cmd]));
    }
    const double rms_v = std::sqrt(sum_v2 / static_cast<double>(csv.rows.size() - 1));
    EXPECT_GT(moved, 0.05) << name << " did not move";
    EXPECT_LE(s.joints[j].rms_tracking_error_rad, 1.5 * (tau + dt) * rms_v + 2 * tick) << name;
    EXPECT_GT(s.joints[j].rms_tracking_error_rad, 0.0) << name;
  }
  // Every servo is back home at the end.
  for (const auto& bus : rig.config().buses) {
    for (const auto& a : bus.actuators) {
      EXPECT_NEAR(rig.sims[0]->device_position(a.device_id), 0.0, 0.02) << a.joint;
    }
  }
}

TEST(QuadrupedLockstep, SameRunSameTelemetry) {
  const std::string a = ::testing::TempDir() + "/lockstep_a.csv";
  const std::string b = ::testing::TempDir() + "/lockstep_b.csv";
  RunSummary sa, sb;
  {
    Rig rig;
    sa = rig.run(1.0, a);
  }
  {
    Rig rig;
    sb = rig.run(1.0, b);
  }
  EXPECT_EQ(test::lockstep_problems(sa), "");
  EXPECT_EQ(test::lockstep_problems(sb), "");
  EXPECT_GT(sa.cycles, 200u);
  EXPECT_GT(std::filesystem::file_size(a), 1000u);
  EXPECT_EQ(test::first_difference(a, b), "");
}

// Checks a fault run: the faulted joint is reported, every other joint's
// command stays continuous and ends at home, and the loop did not stall.
void expect_safe_fault_stop(const RunSummary& s, const Csv& csv, const RobotConfig& config,
                            const std::string& faulted_joint) {
  EXPECT_EQ(s.end_reason, EndReason::fault);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find(faulted_joint), std::string::npos) << s.faults[0];
  const double dt = 1.0 / config.rate_hz;
  for (const auto& joint : config.joints) {
    const int cmd = csv.column(joint.name + "_cmd_rad");
    for (std::size_t k = 1; k < csv.rows.size(); ++k) {
      ASSERT_LE(std::abs(csv.rows[k][cmd] - csv.rows[k - 1][cmd]),
                joint.limits.max_velocity * dt * (1 + 1e-9))
          << joint.name << " jumped at cycle " << k;
    }
    if (joint.name != faulted_joint) {
      EXPECT_NEAR(csv.rows.back()[cmd], joint.home, 1e-6) << joint.name;
    }
  }
  for (const auto& d : s.devices) EXPECT_EQ(d.status.faulted, d.joint == faulted_joint) << d.joint;
}

TEST(QuadrupedLockstep, ADeviceThatDiesMidRunFaultsAndTheOthersRampHome) {
  Rig rig;
  const int dead_id = 5;  // rf_knee
  rig.probe->on_sample = [&](double t) {
    if (t >= 1.0) rig.sims[0]->set_device_responding(dead_id, false);
  };
  const std::string csv_path = ::testing::TempDir() + "/lockstep_dead.csv";
  RunSummary s = rig.run(5.0, csv_path);
  Csv csv = read_csv(csv_path);
  expect_safe_fault_stop(s, csv, rig.config(), "rf_knee");
  EXPECT_NE(s.faults[0].find("no valid answer"), std::string::npos) << s.faults[0];
  EXPECT_LT(s.motion_time_s, 1.5);  // the motion stopped soon after the fault
  for (const auto& d : s.devices) {
    if (d.joint == "rf_knee") {
      // Silent for the watchdog time (0.1 s = 20 cycles), then left out of
      // the cycle; deactivate tries its torque-off up to three times more.
      EXPECT_GE(d.status.timeouts, 20u);
      EXPECT_LE(d.status.timeouts, 25u);
    } else {
      EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
    }
  }
}

TEST(QuadrupedLockstep, AHardwareErrorFaultsTheDeviceAtOnce) {
  Rig rig;
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.5) rig.sims[0]->set_device_hardware_error(9, 0x04);  // lh_ankle overheating
  };
  const std::string csv_path = ::testing::TempDir() + "/lockstep_hw.csv";
  RunSummary s = rig.run(5.0, csv_path);
  Csv csv = read_csv(csv_path);
  expect_safe_fault_stop(s, csv, rig.config(), "lh_ankle");
  EXPECT_NE(s.faults[0].find("hardware error"), std::string::npos) << s.faults[0];
  EXPECT_LT(s.motion_time_s, 0.52);
  for (const auto& d : s.devices) {
    if (d.joint == "lh_ankle") {
      EXPECT_GE(d.status.hardware_errors, 1u);
    }
  }
}

// The rig plays the motion as `animrt run` does, the stop's wind-down
// included: the walk goes on stepping after the request (its walk/stand
// blend, 1 s), then ramps home.
TEST(QuadrupedLockstep, AStopRequestWindsTheWalkDownFirst) {
  Rig rig;
  RunControls controls;
  double last = 0.0;
  rig.probe->on_sample = [&](double t) {
    last = t;
    if (t >= 0.7) controls.stop.store(true);
  };
  RunOptions options = rig.options(0.0);
  options.controls = &controls;
  RunSummary s = rig.run(options);
  EXPECT_EQ(s.end_reason, EndReason::signal);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_NEAR(s.motion_time_s, 0.7, 0.011);
  EXPECT_GT(last, 0.7 + 0.5);
  EXPECT_TRUE(s.stop_warnings.empty());
}

TEST(QuadrupedLockstep, AStopRequestRampsHome) {
  Rig rig;
  RunControls controls;
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.7) controls.stop.store(true);
  };
  const std::string csv_path = ::testing::TempDir() + "/lockstep_stop.csv";
  RunOptions options = rig.options(0.0, csv_path);  // forever, until the stop request
  options.controls = &controls;
  RunSummary s = rig.run(options);
  EXPECT_EQ(s.end_reason, EndReason::signal);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_NEAR(s.motion_time_s, 0.7, 0.011);
  Csv csv = read_csv(csv_path);
  for (const auto& joint : rig.config().joints) {
    EXPECT_NEAR(csv.rows.back()[csv.column(joint.name + "_cmd_rad")], joint.home, 1e-6);
  }
}

TEST(QuadrupedLockstep, AMissingDeviceStopsBringUpBeforeAnythingMoves) {
  Rig rig;
  rig.sims[0]->set_device_responding(3, false);
  try {
    rig.run(1.0);
    FAIL() << "expected a DeviceError";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("lf_ankle"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace animrt
