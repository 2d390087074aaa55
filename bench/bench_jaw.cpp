// The jaw's lip-sync latency on the wall clock: the head robot
// (configs/robots/head.yaml) runs in real time on its simulated Dynamixel
// servos with live sound from a FIFO (capture: pipe:PATH), which a writer
// thread feeds as a capture device would: 5 ms periods, each written when
// its last sample has been "captured" on CLOCK_MONOTONIC. Bursts of a
// voiced sound start at known samples, at random phases; measured: from the
// burst's first sample to the first bus write whose jaw goal leaves closed.
//
//   build/bin/bench_jaw [seconds]

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/head/audio_input.hpp"
#include "animrt/controllers/head/head_source.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

const std::string kRoot = ANIMRT_SOURCE_DIR;
constexpr int kRate = 24000;
constexpr int kPeriod = 120;  // 5 ms

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1000000000 + ts.tv_nsec;
}

struct Pending {
  std::atomic<std::int64_t> onset_ns{-1};  // the burst's first sample, or -1
  std::vector<double> latencies_ms;        // the bus thread's, read after the run
  double writer_late_ms = 0;               // the stand-in's worst write after its period's end
};

// Stamps the first write whose jaw goal (the bus's 4th servo) leaves closed.
class JawStampBus final : public ActuatorBus {
 public:
  JawStampBus(std::unique_ptr<ActuatorBus> bus, Pending& pending)
      : bus_(std::move(bus)), pending_(pending) {}
  const BusConfig& config() const override { return bus_->config(); }
  void configure() override { bus_->configure(); }
  void activate() override { bus_->activate(); }
  void deactivate() override { bus_->deactivate(); }
  void arm_device_guard() override { bus_->arm_device_guard(); }
  void read(std::span<double> positions) override { bus_->read(positions); }
  void write(std::span<const double> positions) override {
    bus_->write(positions);
    const std::int64_t onset = pending_.onset_ns.load();
    const std::int64_t now = now_ns();
    if (onset >= 0 && now >= onset && positions.size() > 3 && positions[3] > deg_to_rad(0.05)) {
      pending_.latencies_ms.push_back(static_cast<double>(now - onset) * 1e-6);
      pending_.onset_ns.store(-1);
    }
  }
  void mark_faulted(std::size_t device) override { bus_->mark_faulted(device); }
  void switch_off(std::size_t device) override { bus_->switch_off(device); }
  bool reads_health() const override { return bus_->reads_health(); }
  std::span<DeviceStatus> devices() override { return bus_->devices(); }

 private:
  std::unique_ptr<ActuatorBus> bus_;
  Pending& pending_;
};

// Feeds the FIFO at the sample clock: silence, and every 0.6 s (+ a random
// phase) a 0.2 s burst; posts each burst's onset before writing it.
void feed(const std::string& fifo, double seconds, Pending& pending,
          const std::atomic<bool>& ended) {
  int fd = -1;  // once the head has opened it for reading
  while (fd < 0 && !ended.load()) {
    fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (fd < 0) return;
  ::fcntl(fd, F_SETFL, 0);
  std::mt19937 random(3);
  const std::int64_t t0 = now_ns();
  std::int64_t next_onset = static_cast<std::int64_t>(kRate * 2.5);  // past the start ramp
  std::int64_t burst_end = -1;
  std::vector<std::int16_t> period(kPeriod);
  for (std::int64_t n = 0; n < static_cast<std::int64_t>(seconds * kRate) && !ended.load();
       n += kPeriod) {
    for (int i = 0; i < kPeriod; ++i) {
      const std::int64_t s = n + i;
      if (s == next_onset) {
        pending.onset_ns.store(t0 + s * 1000000000 / kRate);
        burst_end = s + kRate / 5;
        next_onset = s + kRate * 6 / 10 + static_cast<std::int64_t>(random() % 1200);
      }
      const double v = s < burst_end ? 0.3 * std::sin(2 * std::numbers::pi * 180.0 * s / kRate) : 0;
      period[static_cast<std::size_t>(i)] = static_cast<std::int16_t>(std::lround(v * 32767));
    }
    // The period is "captured" when its last sample is: then it is readable.
    const std::int64_t due = t0 + (n + kPeriod) * 1000000000 / kRate;
    for (std::int64_t w; (w = due - now_ns()) > 0;)
      std::this_thread::sleep_for(std::chrono::nanoseconds(w));
    pending.writer_late_ms =
        std::max(pending.writer_late_ms, static_cast<double>(now_ns() - due) * 1e-6);
    if (::write(fd, period.data(), period.size() * 2) < 0) break;
  }
  ::close(fd);
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 30.0;
  const std::string fifo = "/tmp/bench_jaw_" + std::to_string(::getpid()) + ".fifo";
  ::unlink(fifo.c_str());
  if (::mkfifo(fifo.c_str(), 0600) != 0) return 1;
  LoadedRobot robot = load_robot(kRoot + "/configs/robots/head.yaml");
  robot.config.safety.watchdog_timeout_s = 1.0;  // a busy machine's stall is not the jaw's
  head::HeadMotionConfig c = *robot.config.motion.head;
  c.audio.clear();
  c.capture = std::string(head::kPipeCapturePrefix) + fifo;
  c.audio_device = "none";
  robot.motion = head::make_head_source(c, robot.config.joints);
  Pending pending;
  pending.latencies_ms.reserve(4096);
  SimulatedBackend simulated;
  FigureOptions options;
  options.wrap_bus = [&](std::unique_ptr<ActuatorBus> bus, std::size_t) {
    return std::unique_ptr<ActuatorBus>(std::make_unique<JawStampBus>(std::move(bus), pending));
  };
  Figure figure(std::move(robot), simulated, options);
  RunControls controls;
  RunOptions run = figure.run_options();
  run.controls = &controls;
  std::atomic<bool> ended{false};
  std::thread writer([&] {
    feed(fifo, seconds, pending, ended);
    controls.stop.store(true);
  });
  const RunSummary summary = figure.run(run);
  ended.store(true);
  writer.join();
  ::unlink(fifo.c_str());
  std::vector<double> v = pending.latencies_ms;
  std::sort(v.begin(), v.end());
  auto pct = [&v](double p) {
    return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<std::size_t>(p * v.size()))];
  };
  std::printf(
      "jaw, live sound (FIFO at the sample clock, 10 ms blocks): %zu bursts | first sample -> bus "
      "write p50 %.2f p99 %.2f max %.2f ms (the stand-in wrote up to %.2f ms late) | loop %.0f Hz "
      "%s, overruns %llu, ended by %s\n",
      v.size(), pct(0.5), pct(0.99), pct(1.0), pending.writer_late_ms, figure.config().rate_hz,
      summary.sched_fifo ? "SCHED_FIFO" : "SCHED_OTHER",
      static_cast<unsigned long long>(summary.overruns), to_string(summary.end_reason));
  return 0;
}
