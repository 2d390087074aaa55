// BusWorker: the I/O thread gets its scheduling at creation, and a refusal
// is reported, never fatal. A fatal-error handler's request reaches every
// running I/O thread, which switches its bus off and touches it no more.

#include "../../runtime/src/bus_worker.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <vector>

#include "../../runtime/src/futex.hpp"
#include "animrt/runtime/emergency_stop.hpp"

namespace animrt {
namespace {

// Records the scheduling policy of the thread that reads it.
class PolicyBus final : public ActuatorBus {
 public:
  const BusConfig& config() const override { return config_; }
  void configure() override {}
  void activate() override {}
  void deactivate() override {}
  void read(std::span<double>) override {
    int policy = -1;
    sched_param param{};
    pthread_getschedparam(pthread_self(), &policy, &param);
    policy_ = policy;
  }
  void write(std::span<const double>) override {}
  std::span<DeviceStatus> devices() override { return status_; }
  std::atomic<int> policy_{-2};

 private:
  BusConfig config_;
  std::vector<DeviceStatus> status_;
};

void one_read(BusWorker& worker, std::atomic<std::uint32_t>& done) {
  const std::uint32_t seen = done.load();
  worker.post_read();
  while (!worker.read_done()) futex_wait_until(done, seen, MonotonicClock().now() + 100'000'000);
}

TEST(BusWorker, RealtimePriorityTakesEffectOrIsReported) {
  PolicyBus bus;
  std::atomic<std::uint32_t> done{0};
  std::vector<double> initial(1, 0.0);
  BusWorker worker(bus, initial, done);
  const bool took = worker.start(10);
  EXPECT_EQ(took, worker.realtime());
  one_read(worker, done);
  EXPECT_EQ(bus.policy_.load() == SCHED_FIFO, took);
  EXPECT_FALSE(worker.priority_note().empty());
  if (!took) {
    EXPECT_NE(worker.priority_note().find("not permitted"), std::string::npos);
  }
  worker.stop();
}

TEST(BusWorker, NoPriorityAskedIsANormalThread) {
  PolicyBus bus;
  std::atomic<std::uint32_t> done{0};
  std::vector<double> initial(1, 0.0);
  BusWorker worker(bus, initial, done);
  EXPECT_TRUE(worker.start(0));
  EXPECT_FALSE(worker.realtime());
  one_read(worker, done);
  EXPECT_EQ(bus.policy_.load(), SCHED_OTHER);
  worker.stop();
}

// Counts what the I/O thread does with it.
class CountingBus final : public ActuatorBus {
 public:
  const BusConfig& config() const override { return config_; }
  void configure() override {}
  void activate() override {}
  void deactivate() override { ++deactivations; }
  void read(std::span<double>) override { ++reads; }
  void write(std::span<const double>) override {}
  std::span<DeviceStatus> devices() override { return status_; }
  std::atomic<int> deactivations{0};
  std::atomic<int> reads{0};

 private:
  BusConfig config_;
  std::vector<DeviceStatus> status_;
};

TEST(EmergencyTorqueOff, EveryRunningBusThreadSwitchesItsBusOffAndStops) {
  CountingBus first, second;
  std::atomic<std::uint32_t> done{0};
  std::vector<double> initial(1, 0.0);
  BusWorker a(first, initial, done), b(second, initial, done);
  a.start(0);
  b.start(0);
  one_read(a, done);
  const EmergencyResult r = emergency_torque_off(5'000'000'000);
  EXPECT_EQ(r.buses, 2);
  EXPECT_EQ(r.switched_off, 2);
  EXPECT_EQ(first.deactivations.load(), 1);
  EXPECT_EQ(second.deactivations.load(), 1);
  // Asked again (a terminate handler's abort() comes back as SIGABRT): the
  // buses are not switched off twice, and the threads touch them no more.
  const EmergencyResult again = emergency_torque_off(5'000'000'000);
  EXPECT_EQ(again.switched_off, 2);
  a.post_read();
  usleep(20'000);
  EXPECT_EQ(first.reads.load(), 1);
  EXPECT_EQ(first.deactivations.load(), 1);
  a.stop();
  b.stop();
  // Stopped threads leave nothing to switch off, and free their slots clean.
  EXPECT_EQ(emergency_torque_off(0).buses, 0);
  CountingBus third;
  BusWorker c(third, initial, done);
  c.start(0);
  one_read(c, done);
  EXPECT_EQ(third.deactivations.load(), 0);
  c.stop();
}

}  // namespace
}  // namespace animrt
