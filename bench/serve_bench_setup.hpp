// Shared by the `animrt serve` trigger benches: the simulated animatronic
// figure serving its shipped cues in real time, a sender thread that sends
// triggers at random phases of the cycle, and the neck bus that stamps the
// first write of the cycle that began each awaited cue.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace animrt::serve_bench {

inline std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1000000000 + ts.tv_nsec;
}

// What the sender waits for: the cue it asked for, sent at this time.
struct Pending {
  std::atomic<int> cue{-1};
  std::atomic<std::int64_t> sent_ns{0};
  std::atomic<std::int64_t> latency_ns{-1};
};

// A bus that stamps its first write of the cycle that began the awaited cue.
class StampingBus final : public ActuatorBus {
 public:
  StampingBus(std::unique_ptr<ActuatorBus> bus, const CuePlayer& player, Pending& pending)
      : bus_(std::move(bus)), player_(player), pending_(pending) {}
  const BusConfig& config() const override { return bus_->config(); }
  void configure() override { bus_->configure(); }
  void activate() override { bus_->activate(); }
  void deactivate() override { bus_->deactivate(); }
  void arm_device_guard() override { bus_->arm_device_guard(); }
  void read(std::span<double> positions) override { bus_->read(positions); }
  void write(std::span<const double> positions) override {
    bus_->write(positions);
    const int cue = pending_.cue.load();
    if (cue >= 0 && player_.current_cue() == cue && pending_.latency_ns.load() < 0) {
      pending_.latency_ns.store(now_ns() - pending_.sent_ns.load());
    }
  }
  void mark_faulted(std::size_t device) override { bus_->mark_faulted(device); }
  void switch_off(std::size_t device) override { bus_->switch_off(device); }
  bool reads_health() const override { return bus_->reads_health(); }
  std::span<DeviceStatus> devices() override { return bus_->devices(); }

 private:
  std::unique_ptr<ActuatorBus> bus_;
  const CuePlayer& player_;
  Pending& pending_;
};

inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

struct Measured {
  std::vector<double> latencies_ms;
  int missed = 0;
};

// Sends the triggers, each once the last crossfade has ended, and waits for
// each to reach the bus. `send` sends the trigger for cue i % 2 of
// {look_left, hello}.
inline void send_triggers(const std::function<void(int)>& send, int triggers,
                          const CuePlayer& player, Pending& pending, const std::atomic<bool>& ended,
                          Measured& measured) {
  std::mt19937 random(7);
  std::this_thread::sleep_for(std::chrono::seconds(3));  // past the start ramp
  const char* names[] = {"look_left", "hello"};
  for (int i = 0; i < triggers && !ended.load(); ++i) {
    const auto fade = std::chrono::duration<double>(player.last_crossfade_s());
    std::this_thread::sleep_for(fade + std::chrono::microseconds(100000 + random() % 10000));
    pending.latency_ns.store(-1);
    pending.cue.store(find_cue(player.cues(), names[i % 2]));
    pending.sent_ns.store(now_ns());
    send(i);
    const std::int64_t give_up = now_ns() + 1000000000;
    while (pending.latency_ns.load() < 0 && now_ns() < give_up) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    const std::int64_t l = pending.latency_ns.load();
    pending.cue.store(-1);
    if (l < 0) {
      ++measured.missed;
    } else {
      measured.latencies_ms.push_back(static_cast<double>(l) * 1e-6);
    }
  }
}

struct CaseResult {
  Measured measured;
  RunSummary summary;
  double rate_hz = 0.0;
};

// The animatronic figure and its cue player; a bench makes its receiver from
// requests() (before run(), so it is listening when the sender starts).
class ServedFigure {
 public:
  ServedFigure() : robot_(load_robot(root() + "/configs/robots/animatronic.yaml")) {
    // The simulated devices share a busy machine: a device silent for 0.1 s
    // (the shipped watchdog) there is the machine's stall, not the trigger's.
    robot_.config.safety.watchdog_timeout_s = 1.0;
    LoadedCues loaded = load_cues(root() + "/configs/cues/animatronic.yaml", robot_.config);
    dmx_values_ = loaded.dmx_values;
    auto owned = std::make_unique<CuePlayer>(std::move(loaded.cues), loaded.idle,
                                             robot_.config.joints, requests_);
    player_ = owned.get();
    robot_.motion = std::move(owned);
  }

  CueRequests& requests() { return requests_; }
  const CuePlayer& player() const { return *player_; }
  const std::vector<int>& dmx_values() const { return dmx_values_; }

  // Serves the figure until the sender has sent `triggers` (or a fault ends
  // the run), with a thread spinning at ordinary priority if `load`. Once.
  CaseResult run(const std::function<void(int)>& send, int triggers, bool load = false) {
    SimulatedBackend simulated;
    FigureOptions options;
    options.wrap_bus = [&](std::unique_ptr<ActuatorBus> bus, std::size_t index) {
      return index == 0 ? std::make_unique<StampingBus>(std::move(bus), *player_, pending_)
                        : std::move(bus);
    };
    Figure figure(std::move(robot_), simulated, options);
    RunControls controls;
    RunOptions run = figure.run_options();
    run.controls = &controls;
    std::atomic<bool> spinning{load};
    std::vector<std::thread> spinners;
    if (load) {
      spinners.emplace_back([&spinning] {
        volatile std::uint64_t x = 0;
        while (spinning.load(std::memory_order_relaxed)) x = x + 1;
      });
    }
    CaseResult result;
    std::atomic<bool> ended{false};  // a fault ends the run early
    std::thread sender([&] {
      send_triggers(send, triggers, *player_, pending_, ended, result.measured);
      controls.stop.store(true);
    });
    result.summary = figure.run(run);
    ended.store(true);
    sender.join();
    spinning.store(false);
    for (auto& t : spinners) t.join();
    result.rate_hz = figure.config().rate_hz;
    return result;
  }

 private:
  static std::string root() { return ANIMRT_SOURCE_DIR; }

  CueRequests requests_;  // the player's, so made first
  LoadedRobot robot_;
  const CuePlayer* player_ = nullptr;
  std::vector<int> dmx_values_;
  Pending pending_;
};

// One line per case; `label` padded to `width`, `sent` names the send.
inline void print_case(const char* label, int width, const char* sent, const CaseResult& r) {
  const std::vector<double>& l = r.measured.latencies_ms;
  std::printf(
      "%-*s triggers %4zu (missed %d) | %s -> bus write p50 %6.2f p99 %6.2f max %6.2f "
      "ms | loop %3.0f Hz %s, overruns %llu, ended by %s\n",
      width, label, l.size(), r.measured.missed, sent, percentile(l, 0.5), percentile(l, 0.99),
      percentile(l, 1.0), r.rate_hz, r.summary.sched_fifo ? "SCHED_FIFO" : "SCHED_OTHER",
      static_cast<unsigned long long>(r.summary.overruns), to_string(r.summary.end_reason));
  if (r.summary.end_reason == EndReason::fault)
    std::printf("%s", format_summary(r.summary).c_str());
}

}  // namespace animrt::serve_bench
