// A lockstep run on simulated servos does not depend on the wall clock: an
// answer is missing only once the simulated devices have settled without it
// (bridge/lockstep_line.hpp), so a device thread that runs late, however
// late, changes nothing in the run.

#include "animrt/bridge/lockstep_line.hpp"

#include <gtest/gtest.h>

#include <string>

#include "animrt/runtime/runner.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

const std::string kLineQuadruped =
    std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";

// The rf_knee servo's answers from 0.3 s on leave `late_s` of real time late
// (its thread ran late), two of them.
RunSummary run_with_late_answers(double late_s, const std::string& csv) {
  test::SimRig rig(kLineQuadruped);
  bool delayed = false;
  rig.probe->on_sample = [&](double t) {
    if (t >= 0.3 && !delayed && late_s > 0) {
      rig.sim("legs").set_device_answer_delay(5, from_seconds(late_s), 2);
      delayed = true;
    }
  };
  return rig.run(0.6, csv);
}

TEST(LockstepLine, AnAnswerLaterOnTheWallClockThanTheBusTimeoutChangesNothing) {
  const double late_s = kLockstepMinTimeoutS + 0.15;  // past every lockstep bus timeout
  const std::string on_time = ::testing::TempDir() + "/line_on_time.csv";
  const std::string late = ::testing::TempDir() + "/line_late.csv";
  const RunSummary a = run_with_late_answers(0.0, on_time);
  const RunSummary b = run_with_late_answers(late_s, late);
  EXPECT_EQ(b.end_reason, EndReason::duration);
  EXPECT_EQ(test::lockstep_problems(a), "");
  EXPECT_EQ(test::lockstep_problems(b), "");
  EXPECT_EQ(a.cycles, b.cycles);
  EXPECT_EQ(test::first_difference(on_time, late), "");
}

TEST(LockstepLine, SettlesOnceTheDeviceSideTookEveryByteAndItsAnswersWereRead) {
  LockstepLine line;
  line.device_serving(true);
  EXPECT_TRUE(line.settled());  // nothing asked, nothing to read
  line.host_wrote(10);
  EXPECT_FALSE(line.settled());  // the devices have not taken the request yet
  line.device_wrote(6);
  line.device_took(10);
  EXPECT_FALSE(line.settled());  // an answer is still on its way
  EXPECT_EQ(line.unread(), 6u);
  line.host_read(6);
  EXPECT_TRUE(line.settled());
  EXPECT_EQ(line.unread(), 0u);
  line.host_wrote(4);
  line.device_took(4);  // taken, never answered: a silent device
  EXPECT_TRUE(line.settled());
}

TEST(LockstepLine, AStoppedDeviceSideAnswersNothingAtOnce) {
  LockstepLine line;
  line.device_serving(true);
  line.host_wrote(8);
  EXPECT_FALSE(line.settled());
  line.device_serving(false);  // its thread stopped: nobody takes the bytes
  EXPECT_TRUE(line.settled());
  line.device_serving(true);  // started again: the queued bytes are its to take
  EXPECT_FALSE(line.settled());
  line.device_took(8);
  EXPECT_TRUE(line.settled());
}

}  // namespace
}  // namespace animrt
