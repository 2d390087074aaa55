// The quadruped in lockstep with its twelve simulated servos read through
// Fast Sync Read: the same run as quadruped_lockstep_test.cpp's, with servos
// that report a firmware new enough for it.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "support/files.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// configs/robots/quadruped.yaml with XL430-W250 servos on firmware 46 and
// the given fast_read setting.
std::string quadruped_with(const std::string& fast_read) {
  std::ifstream in(kConfigsDir + "/robots/quadruped.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  text = replaced(text, "    timeout_ms: 4",
                  "    fast_read: " + fast_read + "\n    model: XL430-W250\n    timeout_ms: 4");
  text = replaced(text, "    sim:", "    sim:\n      firmware_version: 46");
  text = replaced(text, "file: ../gaits/walk.yaml", "file: " + kConfigsDir + "/gaits/walk.yaml");
  text = replaced(text, "model: ../models/quadruped.xml",
                  "model: " + kConfigsDir + "/models/quadruped.xml");
  const std::string path = ::testing::TempDir() + "/quadruped_fast_" + fast_read + ".yaml";
  std::ofstream(path) << text;
  return path;
}

TEST(QuadrupedFastRead, WalksInLockstepReadingThroughFastSyncRead) {
  test::SimRig rig(quadruped_with("auto"));
  const std::string csv = ::testing::TempDir() + "/quadruped_fast.csv";
  const RunSummary s = rig.run(2.0, csv);
  EXPECT_EQ(s.end_reason, EndReason::duration);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_TRUE(s.faults.empty());
  auto* bus = dynamic_cast<DynamixelBus*>(&rig.bus(0));
  ASSERT_NE(bus, nullptr);
  EXPECT_TRUE(bus->fast_read_active());
  ASSERT_EQ(s.devices.size(), 12u);
  for (const auto& d : s.devices) {
    EXPECT_EQ(d.status.timeouts, 0u) << d.joint;
    EXPECT_EQ(d.status.crc_errors, 0u) << d.joint;
    EXPECT_EQ(d.status.protocol_errors, 0u) << d.joint;
    EXPECT_GE(d.status.transactions, s.cycles) << d.joint;
  }
  for (const auto& j : s.joints) EXPECT_LT(j.rms_tracking_error_rad, 0.05) << j.name;
}

TEST(QuadrupedFastRead, FastAndPlainReadsGiveTheSameRun) {
  // Lockstep: the telemetry depends on what was read, not how.
  const std::string a = ::testing::TempDir() + "/quadruped_on.csv";
  const std::string b = ::testing::TempDir() + "/quadruped_off.csv";
  RunSummary sa, sb;
  {
    test::SimRig rig(quadruped_with("on"));
    sa = rig.run(1.0, a);
  }
  {
    test::SimRig rig(quadruped_with("off"));
    sb = rig.run(1.0, b);
  }
  // A cycle without a fresh read would keep the last measurement and differ.
  EXPECT_EQ(test::lockstep_problems(sa), "");
  EXPECT_EQ(test::lockstep_problems(sb), "");
  EXPECT_GT(sa.cycles, 150u);
  EXPECT_GT(std::filesystem::file_size(a), 1000u);
  EXPECT_EQ(test::first_difference(a, b), "");
}

}  // namespace
}  // namespace animrt
