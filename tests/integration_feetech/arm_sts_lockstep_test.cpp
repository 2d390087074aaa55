// The STS3215 arm (configs/robots/arm_sts.yaml) on its simulated Feetech
// servos over a real pseudo-terminal, in lockstep: it plays its show and
// tracks it within the servo model, and a servo that dies or reports a fault
// is faulted while the others ramp home.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/runtime/runner.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

const std::string kArmConfig = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/arm_sts.yaml";

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

TEST(ArmStsLockstep, PlaysTheShowAndTracksWithinTheServoModel) {
  test::SimRig rig(kArmConfig);
  const std::string csv_path = ::testing::TempDir() + "/arm_sts.csv";
  const RunSummary s = rig.run(5.0, csv_path);
  EXPECT_EQ(s.end_reason, EndReason::duration);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_TRUE(s.faults.empty());
  ASSERT_EQ(s.devices.size(), 6u);
  for (const auto& d : s.devices) {
    EXPECT_FALSE(d.status.faulted) << d.joint;
    EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
    EXPECT_EQ(d.status.crc_errors, 0u) << d.joint;
    EXPECT_EQ(d.status.protocol_errors, 0u) << d.joint;
    EXPECT_EQ(d.status.hardware_errors, 0u) << d.joint;
    EXPECT_GE(d.status.transactions, s.cycles) << d.joint;
  }
  // A first-order servo with time constant tau lags a command moving at v by
  // about tau * v: the RMS error is bounded by tau * RMS(v), plus the
  // one-cycle delay and the step quantisation.
  const double tau = rig.config().buses[0].sim.time_constant_s;
  const double dt = 1.0 / rig.config().rate_hz;
  const double step = 2 * M_PI / 4096;
  const Csv csv = read_csv(csv_path);
  ASSERT_EQ(csv.rows.size(), s.cycles);
  for (std::size_t j = 0; j < s.joints.size(); ++j) {
    const auto& name = s.joints[j].name;
    const int cmd = csv.column(name + "_cmd_rad");
    double sum_v2 = 0.0, lo = 1e9, hi = -1e9;
    for (std::size_t k = 1; k < csv.rows.size(); ++k) {
      const double v = (csv.rows[k][cmd] - csv.rows[k - 1][cmd]) / dt;
      sum_v2 += v * v;
      lo = std::min(lo, csv.rows[k][cmd]);
      hi = std::max(hi, csv.rows[k][cmd]);
    }
    const double rms_v = std::sqrt(sum_v2 / static_cast<double>(csv.rows.size() - 1));
    EXPECT_GT(hi - lo, 0.3) << name << " did not move";
    EXPECT_LE(s.joints[j].rms_tracking_error_rad, 1.5 * (tau + dt) * rms_v + 2 * step) << name;
    EXPECT_GT(s.joints[j].rms_tracking_error_rad, 0.0) << name;
  }
  // The show's pick: the elbow (mounted mirrored, direction -1) reached -40
  // degrees, which its servo saw as a goal above the middle of its range.
  const int elbow = csv.column("elbow_flex_cmd_rad");
  double lowest = 0.0;
  for (const auto& row : csv.rows) lowest = std::min(lowest, row[elbow]);
  EXPECT_LT(lowest, -0.5);
}

void expect_fault_stop(const RunSummary& s, const RobotConfig& config, const std::string& csv_path,
                       const std::string& faulted) {
  EXPECT_EQ(s.end_reason, EndReason::fault);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find(faulted), std::string::npos) << s.faults[0];
  const Csv csv = read_csv(csv_path);
  const double dt = 1.0 / config.rate_hz;
  for (const auto& joint : config.joints) {
    const int cmd = csv.column(joint.name + "_cmd_rad");
    for (std::size_t k = 1; k < csv.rows.size(); ++k) {
      ASSERT_LE(std::abs(csv.rows[k][cmd] - csv.rows[k - 1][cmd]),
                joint.limits.max_velocity * dt * (1 + 1e-9))
          << joint.name << " jumped at cycle " << k;
    }
    if (joint.name != faulted) {
      EXPECT_NEAR(csv.rows.back()[cmd], joint.home, 1e-6) << joint.name;
    }
  }
  for (const auto& d : s.devices) EXPECT_EQ(d.status.faulted, d.joint == faulted) << d.joint;
}

TEST(ArmStsLockstep, AServoThatDiesIsFaultedByTheWatchdogAndTheOthersRampHome) {
  test::SimRig rig(kArmConfig);
  rig.probe->on_sample = [&](double t) {
    if (t >= 1.0) rig.sims[0]->set_device_responding(4, false);  // wrist_flex
  };
  const std::string csv_path = ::testing::TempDir() + "/arm_sts_dead.csv";
  const RunSummary s = rig.run(4.0, csv_path);
  expect_fault_stop(s, rig.config(), csv_path, "wrist_flex");
  EXPECT_LT(s.motion_time_s, 1.5);
  for (const auto& d : s.devices) {
    if (d.joint == "wrist_flex") {
      // Silent for the watchdog time (0.1 s = 10 cycles), then left out.
      EXPECT_GE(d.status.timeouts, 10u);
      EXPECT_LE(d.status.timeouts, 15u);
    } else {
      EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
    }
  }
}

TEST(ArmStsLockstep, AnOverloadFaultsTheServoAtOnce) {
  test::SimRig rig(kArmConfig);
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.5) rig.sims[0]->set_device_hardware_error(6, 0x20);  // gripper overload
  };
  const std::string csv_path = ::testing::TempDir() + "/arm_sts_overload.csv";
  const RunSummary s = rig.run(4.0, csv_path);
  expect_fault_stop(s, rig.config(), csv_path, "gripper");
  EXPECT_LT(s.motion_time_s, 0.53);
  for (const auto& d : s.devices) {
    if (d.joint == "gripper") {
      EXPECT_GE(d.status.hardware_errors, 1u);
      EXPECT_EQ(d.status.hardware_error_status, 0x20);
    }
  }
}

}  // namespace
}  // namespace animrt
