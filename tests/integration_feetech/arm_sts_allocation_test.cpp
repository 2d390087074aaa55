// No allocation on the threads the run owns (the loop thread and the
// Feetech bus's I/O thread), from the first cycle to the last, for the STS3215
// arm in lockstep: start ramp, show, stop ramp with telemetry, and the fault
// paths (a servo dying, a servo reporting an overload). The same watch as
// tests/integration/cycle_allocation_test.cpp.

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "support/alloc_counter.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

using test::RunAllocationWatch;
using test::RunPhase;
using test::RunThread;
using test::SimRig;

const std::string kArm = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/arm_sts.yaml";

test::RigSettings short_ramps() {
  test::RigSettings settings;
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
  };
  return settings;
}

void expect_no_allocation(SimRig& rig, double motion_s, EndReason end,
                          const std::function<void(double)>& inject = {}) {
  RunAllocationWatch watch;
  if (inject) {
    rig.probe->on_sample = [&](double t) {
      const bool open = watch.is_open();
      watch.close();
      inject(t);
      if (open) watch.open();
    };
  }
  const std::string csv = ::testing::TempDir() + "/" +
                          ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".csv";
  const RunSummary s = rig.run_watching(watch, rig.options(motion_s, csv));
  EXPECT_EQ(s.end_reason, end) << (s.faults.empty() ? "" : s.faults[0]);
  ASSERT_TRUE(watch.was_opened()) << "the window never opened: no cycle seen";
  EXPECT_GT(rig.cycles_in(RunPhase::start_ramp), 10u);
  EXPECT_GT(rig.cycles_in(RunPhase::motion), 10u);
  EXPECT_GT(rig.cycles_in(RunPhase::stop_ramp), 10u);
  EXPECT_EQ(watch.started(RunThread::bus_io), 1);
  EXPECT_EQ(s.telemetry_records, s.cycles);
  EXPECT_EQ(watch.counted(), 0u) << "loop thread " << watch.on(RunThread::loop)
                                 << ", bus I/O thread " << watch.on(RunThread::bus_io) << "\n"
                                 << watch.where();
}

TEST(ArmStsAllocation, StartShowStopWithTelemetry) {
  SimRig rig(kArm, short_ramps());
  expect_no_allocation(rig, 1.0, EndReason::duration);
}

TEST(ArmStsAllocation, ServoDyingMidRun) {
  SimRig rig(kArm, short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, EndReason::fault, [&](double t) {
    if (!done && t >= 0.3) rig.sim("arm").set_device_responding(3, false);
    done = done || t >= 0.3;
  });
}

TEST(ArmStsAllocation, ServoOverload) {
  SimRig rig(kArm, short_ramps());
  bool done = false;
  expect_no_allocation(rig, 2.0, EndReason::fault, [&](double t) {
    if (!done && t >= 0.3) rig.sim("arm").set_device_hardware_error(2, 0x20);
    done = done || t >= 0.3;
  });
}

}  // namespace
}  // namespace animrt
