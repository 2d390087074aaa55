// The virtual CAN bus with simulated devices on a lockstep clock: the host's
// receive follows the devices (VirtualCanBus::attach_lockstep_device), never
// the wall clock, in both directions: it waits for a device thread that is
// late, however short its own timeout, and gives up at once, however long
// its timeout, once the devices have served everything at the clock's time.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"

namespace animrt {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::steady_clock;

can_frame lockstep_frame(canid_t id) {
  can_frame f{};
  f.can_id = id;
  f.len = 1;
  return f;
}

TEST(LockstepCan, TheHostWaitsForADeviceThreadThatRunsLate) {
  auto bus = std::make_shared<VirtualCanBus>("ls1");
  ManualClock clock(1000);
  bus->set_clock(&clock);
  auto device = bus->attach_lockstep_device();
  auto host = bus->attach();
  device->serving(true);
  device->served(clock.now());
  ASSERT_TRUE(host->send(lockstep_frame(0x601)));
  // The device thread takes the request only 200 ms of wall time later.
  std::thread late([&] {
    std::this_thread::sleep_for(milliseconds(200));
    can_frame request;
    ASSERT_TRUE(device->receive(request, microseconds(0)));
    device->send(lockstep_frame(0x581));
    device->served(clock.now());
  });
  can_frame answer;
  const bool got = host->receive(answer, microseconds(0));
  late.join();
  ASSERT_TRUE(got);
  EXPECT_EQ(answer.can_id, 0x581u);
  // Served, nothing more will come: no wait, whatever the timeout.
  const auto before = steady_clock::now();
  EXPECT_FALSE(host->receive(answer, std::chrono::seconds(3)));
  EXPECT_LT(steady_clock::now() - before, std::chrono::seconds(1));
  device->serving(false);
  bus->set_clock(nullptr);
}

TEST(LockstepCan, ADeviceIsAskedToPollWhenTheClockMovedAndAStoppedOneIsNotWaitedFor) {
  auto bus = std::make_shared<VirtualCanBus>("ls2");
  ManualClock clock(1000);
  bus->set_clock(&clock);
  auto device = bus->attach_lockstep_device();
  auto host = bus->attach();
  device->serving(true);
  device->served(clock.now());
  // A device thread as CanSimBus runs it: each wake-up, a heartbeat when
  // the clock has reached 2000.
  std::atomic<bool> stop{false};
  std::thread serve([&] {
    bool sent = false;
    while (!stop) {
      can_frame f;
      device->receive(f, milliseconds(20));
      const Nanos now = clock.now();
      if (now >= 2000 && !sent) sent = device->send(lockstep_frame(0x720));
      device->served(now);
    }
  });
  clock.set(2000);
  can_frame heartbeat;
  ASSERT_TRUE(host->receive(heartbeat, microseconds(0)));  // the poll at 2000
  EXPECT_EQ(heartbeat.can_id, 0x720u);
  stop = true;
  serve.join();
  device->serving(false);
  ASSERT_TRUE(host->send(lockstep_frame(0x601)));  // nobody takes it
  const auto before = steady_clock::now();
  EXPECT_FALSE(host->receive(heartbeat, std::chrono::seconds(3)));
  EXPECT_LT(steady_clock::now() - before, std::chrono::seconds(1));
  bus->set_clock(nullptr);
}

}  // namespace
}  // namespace animrt
