// IMU read latency: the simulated BNO08x (UART-RVC, 100 Hz) on a real pty,
// the host's reader thread decoding it into the mailbox the cycle takes
// from. The part encodes its send time in the yaw (a full turn a second,
// 0.01 degree = 28 us), so each reading carries when its frame left.
//
//   bench_imu [seconds]
//
// Prints the latency from a frame's send time to the reader's stamp (bytes
// read) and to the reading taken from the mailbox, as percentiles; a real
// line adds the frame's wire time (19 bytes at 115200 baud), printed too.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <thread>
#include <vector>

#include "animrt/bridge/imu/rvc_reader.hpp"
#include "animrt/sim/imu/rvc_sim_imu.hpp"

namespace {

using namespace animrt;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

// Seconds from a to b, both fractions of a second (b later, within a second).
double since(double a, double b) {
  double d = b - a;
  if (d < 0.0) d += 1.0;
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  const MonotonicClock clock;
  const Nanos start = clock.now();
  ImuConfig config;
  config.name = "bench";
  config.protocol = "bno08x_rvc";
  sim::RvcSimImu part(config, clock, start, [](double t) {
    const double frac = t - std::floor(t);
    sim::TrunkState s;
    s.quat = quat_from_ypr((frac * 360.0 - 180.0) * std::numbers::pi / 180.0, 0.0, 0.0);
    return s;
  });
  imu::RvcReader reader(open_serial(part.port(), 115200), config, clock, start);
  std::vector<double> to_read, to_taken;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  ImuReading r;
  while (std::chrono::steady_clock::now() < until) {
    if (reader.readings().take(r)) {
      const double taken = to_seconds(clock.now() - start);
      const double sent = (yaw_of(r.quat) * 180.0 / std::numbers::pi + 180.0) / 360.0;
      to_read.push_back(since(sent, r.time_s - std::floor(r.time_s)));
      to_taken.push_back(since(sent, taken - std::floor(taken)));
    }
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
  std::printf("frames: %zu taken of %llu sent, checksum errors %llu, lost %llu\n", to_read.size(),
              static_cast<unsigned long long>(part.frames_sent()),
              static_cast<unsigned long long>(reader.checksum_errors()),
              static_cast<unsigned long long>(reader.lost_frames()));
  for (const auto& [name, v] : {std::pair{"sent -> read (reader's stamp)", &to_read},
                                std::pair{"sent -> taken from the mailbox", &to_taken}}) {
    std::printf("%s: p50 %.0f us, p99 %.0f us, max %.0f us\n", name, 1e6 * percentile(*v, 0.5),
                1e6 * percentile(*v, 0.99), 1e6 * percentile(*v, 1.0));
  }
  std::printf("wire time of one frame at 115200 baud (8N1): %.0f us\n", 19 * 10 / 115200.0 * 1e6);
  return 0;
}
