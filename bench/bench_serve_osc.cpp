// Trigger-to-motion latency of `animrt serve` over OSC: the simulated
// animatronic figure serves its shipped cues in real time; a sender thread
// sends /cue/NAME over UDP on loopback at random phases of the cycle, and
// the time from sendto() to the first bus write of the cycle that began
// the cue (the neck bus's Sync Write) is measured. Run as the machine is and
// with a thread spinning at ordinary priority (added load).
// Each case ends early if a fault ends the run (its summary is printed);
// the devices' silence watchdog is 1 s here, as the machine is shared.
//
//   bench_serve_osc [triggers-per-case]

#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/osc_receiver.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

const std::string kRoot = ANIMRT_SOURCE_DIR;

std::int64_t now_ns() {
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

std::vector<std::uint8_t> osc_cue(const std::string& name) {
  std::vector<std::uint8_t> out;
  for (const std::string& s : {"/cue/" + name, std::string(",")}) {
    out.insert(out.end(), s.begin(), s.end());
    do out.push_back(0);
    while (out.size() % 4 != 0);
  }
  return out;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

struct Measured {
  std::vector<double> latencies_ms;
  int missed = 0;
};

// Sends the triggers, each once the last crossfade has ended, and waits for
// each to reach the bus.
void send_triggers(int port, int triggers, const CuePlayer& player, Pending& pending,
                   const std::atomic<bool>& ended, Measured& measured) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::mt19937 random(7);
  std::this_thread::sleep_for(std::chrono::seconds(3));  // past the start ramp
  const char* names[] = {"look_left", "hello"};
  for (int i = 0; i < triggers && !ended.load(); ++i) {
    const auto fade = std::chrono::duration<double>(player.last_crossfade_s());
    std::this_thread::sleep_for(fade + std::chrono::microseconds(100000 + random() % 10000));
    const std::vector<std::uint8_t> packet = osc_cue(names[i % 2]);
    pending.latency_ns.store(-1);
    pending.cue.store(find_cue(player.cues(), names[i % 2]));
    pending.sent_ns.store(now_ns());
    ::sendto(fd, packet.data(), packet.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
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
  ::close(fd);
}

void run_case(bool load, int triggers) {
  LoadedRobot robot = load_robot(kRoot + "/configs/robots/animatronic.yaml");
  // The simulated devices share a busy machine: a device silent for 0.1 s
  // (the shipped watchdog) there is the machine's stall, not the trigger's.
  robot.config.safety.watchdog_timeout_s = 1.0;
  LoadedCues loaded = load_cues(kRoot + "/configs/cues/animatronic.yaml", robot.config);
  CueRequests requests;
  auto owned = std::make_unique<CuePlayer>(std::move(loaded.cues), loaded.idle, robot.config.joints,
                                           requests);
  const CuePlayer& player = *owned;
  robot.motion = std::move(owned);
  Pending pending;
  // The cue names are the receiver's own: its thread outlives the player.
  std::vector<std::string> cues;
  for (const Cue& cue : player.cues()) cues.push_back(cue.name);
  OscReceiver osc("127.0.0.1", 0, [&requests, cues](const OscMessage& m) {
    const auto found = std::find(cues.begin(), cues.end(), m.address.substr(5));
    if (found != cues.end()) requests.cue(static_cast<int>(found - cues.begin()));
    return found != cues.end();
  });
  SimulatedBackend simulated;
  FigureOptions options;
  options.wrap_bus = [&](std::unique_ptr<ActuatorBus> bus, std::size_t index) {
    return index == 0 ? std::make_unique<StampingBus>(std::move(bus), player, pending)
                      : std::move(bus);
  };
  Figure figure(std::move(robot), simulated, options);
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
  Measured measured;
  std::atomic<bool> ended{false};  // a fault ends the run early
  std::thread sender([&] {
    send_triggers(osc.port(), triggers, player, pending, ended, measured);
    controls.stop.store(true);
  });
  const RunSummary summary = figure.run(run);
  ended.store(true);
  sender.join();
  spinning.store(false);
  for (auto& t : spinners) t.join();
  std::printf(
      "%-34s triggers %4zu (missed %d) | OSC send -> bus write p50 %6.2f p99 %6.2f max %6.2f "
      "ms | loop %3.0f Hz %s, overruns %llu, ended by %s\n",
      load ? "added load (a spinning thread)" : "no added load", measured.latencies_ms.size(),
      measured.missed, percentile(measured.latencies_ms, 0.5),
      percentile(measured.latencies_ms, 0.99), percentile(measured.latencies_ms, 1.0),
      figure.config().rate_hz, summary.sched_fifo ? "SCHED_FIFO" : "SCHED_OTHER",
      static_cast<unsigned long long>(summary.overruns), to_string(summary.end_reason));
  if (summary.end_reason == EndReason::fault) std::printf("%s", format_summary(summary).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const int triggers = argc > 1 ? std::atoi(argv[1]) : 200;
  run_case(false, triggers);
  run_case(true, triggers);
  return 0;
}
