// CAN bus load of the CAN quadruped and how many MIT motors one bus carries.
//
// Bits on the wire of a classical CAN data frame with an 11-bit id and n
// data bytes: 47 + 8n fixed bits (SOF, id, RTR, IDE, r0, DLC, data, CRC 15,
// delimiters, ACK, EOF, 3 bits intermission) plus one stuff bit after every
// five equal bits in SOF..CRC. Worst case: 47 + 8n + floor((34 + 8n - 1) / 4).
// The exact count of each frame is computed here from its bits (CRC-15 poly
// 0x4599 included), from the frames a lockstep run really puts on the
// in-process virtual bus.

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/can/mit_codec.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

int worst_case_bits(int n) { return 47 + 8 * n + (34 + 8 * n - 1) / 4; }

// Exact bits of one standard data frame, stuffing included.
int frame_bits(const can_frame& f) {
  std::vector<int> bits;
  auto push = [&](std::uint32_t v, int count) {
    for (int i = count - 1; i >= 0; --i) bits.push_back((v >> i) & 1);
  };
  push(0, 1);                         // SOF
  push(f.can_id & CAN_SFF_MASK, 11);  // id
  push(0, 1);                         // RTR
  push(0, 1);                         // IDE
  push(0, 1);                         // r0
  push(f.len, 4);                     // DLC
  for (int i = 0; i < f.len; ++i) push(f.data[i], 8);
  std::uint32_t crc = 0;
  for (int b : bits) {
    const int next = b ^ static_cast<int>((crc >> 14) & 1);
    crc = (crc << 1) & 0x7FFF;
    if (next) crc ^= 0x4599;
  }
  push(crc, 15);
  int stuffed = 0, run = 0, last = -1;
  for (int b : bits) {
    if (b == last) {
      ++run;
    } else {
      run = 1;
      last = b;
    }
    if (run == 5) {  // a complement bit follows and starts a new run
      ++stuffed;
      last = !b;
      run = 1;
    }
  }
  return static_cast<int>(bits.size()) + stuffed + 1 + 1 + 1 + 7 + 3;
}

struct Tally {
  std::uint64_t frames = 0, bits = 0, worst = 0;
};

}  // namespace

int main() {
  std::printf("CAN 2.0A frame lengths (bits, incl. 3-bit intermission):\n");
  for (int n : {0, 1, 2, 6, 8}) {
    std::printf("  %d data bytes: %d unstuffed, %d worst case with stuffing\n", n, 47 + 8 * n,
                worst_case_bits(n));
  }

  // --- the CAN quadruped in lockstep, every frame counted per interface ---------
  const std::string path = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";
  LoadedRobot robot = load_robot(path);
  const double rate = robot.config.rate_hz;
  SimulatedBackend simulated;
  FigureOptions lockstep;
  lockstep.lockstep = true;
  lockstep.edit = [](RobotConfig& config) {
    for (auto& bus : config.buses) bus.timeout_s = 0.05;
  };
  Figure figure(std::move(robot), simulated, lockstep);
  std::map<std::string, std::unique_ptr<CanFrameTransport>> sniffers;
  for (const auto& bus : figure.config().buses) {
    if (!sniffers.count(bus.port)) sniffers[bus.port] = open_can(bus.port);
  }
  RunOptions options = figure.run_options();
  options.duration_s = 2.0;
  // Every frame of the run, drained as it goes (the queues are bounded).
  std::map<std::string, Tally> tally;
  for (auto& [port, sniffer] : sniffers) tally[port];
  std::atomic<bool> stop{false};
  std::vector<std::thread> drains;
  for (auto& [port, sniffer] : sniffers) {
    drains.emplace_back([&, s = sniffer.get(), t = &tally[port]] {
      can_frame f;
      for (;;) {
        if (s->receive(f, std::chrono::milliseconds(5))) {
          ++t->frames;
          t->bits += static_cast<std::uint64_t>(frame_bits(f));
          t->worst += static_cast<std::uint64_t>(worst_case_bits(f.len));
        } else if (stop.load()) {
          return;
        }
      }
    });
  }
  const RunSummary summary = figure.run(options);
  stop = true;
  for (auto& d : drains) d.join();
  std::printf(
      "\nCAN quadruped (%s) at %.0f Hz, whole run (%llu cycles incl. ramps and bring-up):\n",
      path.c_str(), rate, static_cast<unsigned long long>(summary.cycles));
  for (const auto& [port, t] : tally) {
    const double cycles = static_cast<double>(summary.cycles);
    const double bits_per_cycle = static_cast<double>(t.bits) / cycles;
    std::printf(
        "  %-14s %5.1f frames/cycle, %6.0f bits/cycle exact (%6.0f worst case): load %.1f%% "
        "of 1 Mbit/s (worst %.1f%%)\n",
        port.c_str(), static_cast<double>(t.frames) / cycles, bits_per_cycle,
        static_cast<double>(t.worst) / cycles, bits_per_cycle * rate / 1e4,
        static_cast<double>(t.worst) / cycles * rate / 1e4);
  }

  // --- MIT motors per bus ------------------------------------------------------
  const mit::Ranges& r = *mit::find_model("ak80-9");
  double exact = 0;
  int samples = 0;
  for (double p = -1.0; p <= 1.0; p += 0.01) {
    mit::Reply reply;
    reply.motor_id = 3;
    reply.position = p;
    reply.velocity = 3 * p;
    reply.torque = -2 * p;
    reply.extended = true;
    reply.temperature = 40;
    exact += frame_bits(mit::pack_command(3, {p, 0, 40, 1, 0}, r)) +
             frame_bits(mit::pack_reply(0, reply, r));
    ++samples;
  }
  const double per_motor = exact / samples;
  const int worst_motor = worst_case_bits(8) + worst_case_bits(8);
  std::printf(
      "\nMIT motor per cycle: command (8 bytes) + reply (8 bytes): %.1f bits typical, %d worst "
      "case\n",
      per_motor, worst_motor);
  for (double hz : {500.0, 1000.0}) {
    const double budget = 1e6 / hz;
    std::printf(
        "  at %4.0f Hz on 1 Mbit/s: %d motors at 100%% load worst case (%d typical); "
        "%d worst case at a 70%% load cap\n",
        hz, static_cast<int>(budget / worst_motor), static_cast<int>(budget / per_motor),
        static_cast<int>(0.7 * budget / worst_motor));
  }

  // --- codec cost ----------------------------------------------------------------
  const int iterations = 2'000'000;
  mit::Reply out;
  volatile std::uint32_t sink = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < iterations; ++i) {
    const can_frame c = mit::pack_command(3, {i * 1e-6, 0, 40, 1, 0}, r);
    mit::unpack_reply(c, r, out);
    sink = sink + c.data[1];
  }
  const double ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
  std::printf("\nMIT pack_command + unpack_reply: %.1f ns per motor\n", ns / iterations);
  return 0;
}
