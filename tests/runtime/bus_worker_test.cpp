// BusWorker: the I/O thread gets its scheduling at creation, and a refusal
// is reported, never fatal.

#include "../../runtime/src/bus_worker.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <vector>

#include "../../runtime/src/futex.hpp"

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

}  // namespace
}  // namespace animrt
