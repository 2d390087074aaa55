// What the service manager hears from a run: ready after the start ramp,
// the watchdog only while cycles complete, stopping with the stop ramp.

#include "animrt/runtime/service_watch.hpp"

#include <gtest/gtest.h>

namespace animrt {
namespace {

using Messages = std::vector<std::string>;

TEST(ServiceWatch, ReadyOnlyOnceTheStartRampHasEndedAndTheMotionPlays) {
  RunHeartbeat beat;
  ServiceWatch watch(true);
  EXPECT_EQ(watch.look(beat), Messages{});  // bring-up: no cycle yet
  beat.beat(Phase::start_ramp);
  EXPECT_EQ(watch.look(beat), Messages{"WATCHDOG=1"});
  beat.beat(Phase::start_ramp);
  EXPECT_EQ(watch.look(beat), Messages{"WATCHDOG=1"});
  beat.beat(Phase::motion);
  EXPECT_EQ(watch.look(beat), (Messages{"READY=1", "WATCHDOG=1"}));
  beat.beat(Phase::motion);
  EXPECT_EQ(watch.look(beat), Messages{"WATCHDOG=1"});
}

TEST(ServiceWatch, AStalledLoopGetsNoWatchdogPing) {
  RunHeartbeat beat;
  ServiceWatch watch(true);
  beat.beat(Phase::motion);
  EXPECT_EQ(watch.look(beat), (Messages{"READY=1", "WATCHDOG=1"}));
  // No cycle completed since the last look: whatever else runs, no ping.
  EXPECT_EQ(watch.look(beat), Messages{});
  EXPECT_EQ(watch.look(beat), Messages{});
  beat.beat(Phase::motion);
  EXPECT_EQ(watch.look(beat), Messages{"WATCHDOG=1"});
}

TEST(ServiceWatch, StoppingOnceWhenTheStopRampBegins) {
  RunHeartbeat beat;
  ServiceWatch watch(true);
  beat.beat(Phase::motion);
  watch.look(beat);
  beat.beat(Phase::stop_ramp);
  EXPECT_EQ(watch.look(beat), (Messages{"WATCHDOG=1", "STOPPING=1"}));
  beat.beat(Phase::stop_ramp);
  EXPECT_EQ(watch.look(beat), Messages{"WATCHDOG=1"});
  beat.end();
  EXPECT_EQ(watch.look(beat), Messages{});
  EXPECT_TRUE(watch.stopping());
}

TEST(ServiceWatch, OnceTheActuatorsAreReleasedTheWatchdogIsFedUntilTheProcessExits) {
  RunHeartbeat beat;
  ServiceWatch watch(true);
  beat.beat(Phase::motion);
  beat.beat(Phase::stop_ramp);
  watch.look(beat);
  beat.end();
  // The loop has ended, the actuators not yet released: no ping.
  EXPECT_EQ(watch.look(beat), Messages{});
  beat.released();
  // No more cycles: only the summary is left to write, however long it takes.
  EXPECT_EQ(watch.look(beat), Messages{"WATCHDOG=1"});
  EXPECT_EQ(watch.look(beat), Messages{"WATCHDOG=1"});
}

TEST(ServiceWatch, AStopDuringTheStartRampIsNeverReady) {
  RunHeartbeat beat;
  ServiceWatch watch(false);
  beat.beat(Phase::start_ramp);
  EXPECT_EQ(watch.look(beat), Messages{});  // no watchdog asked for
  beat.beat(Phase::stop_ramp);
  beat.end();
  EXPECT_EQ(watch.look(beat), Messages{"STOPPING=1"});
  EXPECT_FALSE(watch.ready());
}

}  // namespace
}  // namespace animrt
