// Trigger-to-motion latency of `animrt serve` per trigger source (Art-Net,
// sACN, MIDI as a raw byte stream through a FIFO): the simulated animatronic
// figure serves its shipped cues in real time; a sender thread sends each
// trigger at a random phase of the cycle, and the time from the send (the
// sendto() or write()) to the first bus write of the cycle that began the
// cue (the neck bus's Sync Write) is measured. OSC: bench_serve_osc.
// Each case ends early if a fault ends the run (its summary is printed);
// the devices' silence watchdog is 1 s here, as the machine is shared.
//
//   bench_serve_triggers [triggers-per-source]

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/artnet_receiver.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/midi_input.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/sacn_receiver.hpp"
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

// The trigger packets, written from the protocols' layouts.
std::vector<std::uint8_t> artdmx(int value) {
  std::vector<std::uint8_t> p = {'A',
                                 'r',
                                 't',
                                 '-',
                                 'N',
                                 'e',
                                 't',
                                 0,
                                 0x00,
                                 0x50,
                                 0,
                                 14,
                                 0,
                                 0,
                                 0,
                                 0,
                                 0,
                                 2,
                                 static_cast<std::uint8_t>(value),
                                 0};
  return p;
}

std::vector<std::uint8_t> e131(int value, int sequence) {
  std::vector<std::uint8_t> p(128, 0);
  auto put16 = [&p](std::size_t at, unsigned v) {
    p[at] = static_cast<std::uint8_t>(v >> 8);
    p[at + 1] = static_cast<std::uint8_t>(v);
  };
  put16(0, 0x0010);
  const char id[] = "ASC-E1.17";
  std::copy(id, id + 9, p.begin() + 4);
  put16(16, 0x7000 | (128 - 16));
  p[21] = 4;
  put16(38, 0x7000 | (128 - 38));
  p[43] = 2;
  p[108] = 100;
  p[111] = static_cast<std::uint8_t>(sequence);
  put16(113, 1);
  put16(115, 0x7000 | (128 - 115));
  p[117] = 2;
  p[118] = 0xa1;
  put16(121, 1);
  put16(123, 3);
  p[126] = static_cast<std::uint8_t>(value);
  return p;
}

enum class Source { artnet, sacn, midi };
const char* source_name(Source s) {
  return s == Source::artnet ? "Art-Net (ArtDmx)"
         : s == Source::sacn ? "sACN (E1.31)"
                             : "MIDI (FIFO)";
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
// each to reach the bus. `send` sends the trigger for cue name i % 2.
void send_triggers(const std::function<void(int)>& send, int triggers, const CuePlayer& player,
                   Pending& pending, const std::atomic<bool>& ended, Measured& measured) {
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

void run_case(Source source, int triggers) {
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
  // The receiver and its sender: look_left and hello in turn.
  const std::vector<int> values = loaded.dmx_values;
  auto select = [&requests, values](int value) {
    for (std::size_t c = 0; c < values.size(); ++c) {
      if (values[c] == value) requests.cue(static_cast<int>(c));
    }
  };
  const int look = find_cue(player.cues(), "look_left"), hello = find_cue(player.cues(), "hello");
  const int dmx[2] = {values[static_cast<std::size_t>(look)],
                      values[static_cast<std::size_t>(hello)]};
  std::unique_ptr<ArtNetReceiver> artnet;
  std::unique_ptr<SacnReceiver> sacn;
  std::unique_ptr<MidiReceiver> midi;
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const std::string fifo = "/tmp/bench_serve_triggers." + std::to_string(::getpid());
  int midi_fd = -1;
  std::function<void(int)> send;
  if (source == Source::artnet) {
    artnet = std::make_unique<ArtNetReceiver>("127.0.0.1", 0, 0, 1, select);
    to.sin_port = htons(static_cast<std::uint16_t>(artnet->port()));
    send = [&](int i) {
      const auto p = artdmx(dmx[i % 2]);
      ::sendto(fd, p.data(), p.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    };
  } else if (source == Source::sacn) {
    sacn = std::make_unique<SacnReceiver>("127.0.0.1", 0, false, 1, 1, select);
    to.sin_port = htons(static_cast<std::uint16_t>(sacn->port()));
    send = [&](int i) {
      const auto p = e131(dmx[i % 2], i);
      ::sendto(fd, p.data(), p.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    };
  } else {
    ::mkfifo(fifo.c_str(), 0600);
    midi = std::make_unique<MidiReceiver>(
        fifo, std::vector<MidiBinding>{{look, false, 60, 0}, {hello, false, 61, 0}},
        [&requests](int cue) { requests.cue(cue); });
    midi_fd = ::open(fifo.c_str(), O_WRONLY);
    send = [&](int i) {
      const std::uint8_t note[3] = {0x90, static_cast<std::uint8_t>(60 + i % 2), 100};
      if (::write(midi_fd, note, 3) != 3) std::perror("MIDI write");
    };
  }
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
  Measured measured;
  std::atomic<bool> ended{false};  // a fault ends the run early
  std::thread sender([&] {
    send_triggers(send, triggers, player, pending, ended, measured);
    controls.stop.store(true);
  });
  const RunSummary summary = figure.run(run);
  ended.store(true);
  sender.join();
  ::close(fd);
  if (midi_fd >= 0) ::close(midi_fd);
  if (midi) ::unlink(fifo.c_str());
  std::printf(
      "%-20s triggers %4zu (missed %d) | send -> bus write p50 %6.2f p99 %6.2f max %6.2f "
      "ms | loop %3.0f Hz %s, overruns %llu, ended by %s\n",
      source_name(source), measured.latencies_ms.size(), measured.missed,
      percentile(measured.latencies_ms, 0.5), percentile(measured.latencies_ms, 0.99),
      percentile(measured.latencies_ms, 1.0), figure.config().rate_hz,
      summary.sched_fifo ? "SCHED_FIFO" : "SCHED_OTHER",
      static_cast<unsigned long long>(summary.overruns), to_string(summary.end_reason));
  if (summary.end_reason == EndReason::fault) std::printf("%s", format_summary(summary).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const int triggers = argc > 1 ? std::atoi(argv[1]) : 200;
  for (Source s : {Source::artnet, Source::sacn, Source::midi}) run_case(s, triggers);
  return 0;
}
