// What the MCAP recording (`animrt run --record`) costs per cycle of a
// 12-joint figure at 200 Hz: on the loop thread (the ring pushes of joint
// states, loop statistics and, every 20th cycle, 12 devices' status) and on
// the writer thread (JSON, zstd chunks, the file), and the bytes per cycle.
// The cycles are pushed before the writer starts, so the two are timed apart.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "animrt/runtime/mcap_recorder.hpp"

namespace {

constexpr int kCycles = 6000;  // 30 s at 200 Hz: within every ring's capacity

animrt::RobotModel figure() {
  animrt::RobotModel m;
  m.name = "bench";
  m.rate_hz = 200.0;
  animrt::BusModel bus{"legs", {}, {}};
  for (int j = 0; j < 12; ++j) {
    m.joint_names.push_back("joint_" + std::to_string(j));
    bus.joint.push_back(j);
    bus.device_id.push_back(j + 1);
  }
  m.buses.push_back(bus);
  return m;
}

void BM_RecordCycles(benchmark::State& state) {
  const animrt::RobotModel model = figure();
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("bench_recording_" + std::to_string(getpid()) + ".mcap"))
                               .string();
  std::vector<double> cmd(12), meas(12);
  double push_s = 0, write_s = 0, bytes = 0;
  for (auto _ : state) {
    animrt::McapRecorder recorder(path, model);
    const auto t0 = std::chrono::steady_clock::now();
    for (int c = 0; c < kCycles; ++c) {
      const double t = c * 0.005;
      for (std::size_t j = 0; j < 12; ++j) {
        cmd[j] = 0.001 * c + 0.1 * static_cast<double>(j);  // cheap: the push is what is timed
        meas[j] = cmd[j] - 0.002;
      }
      recorder.push_joints(t, cmd, meas);
      recorder.push_loop(t, 0.005, 1e-5 * (c % 7), 4e-5, 0, 0);
      if (c % 20 == 0) {
        for (int d = 0; d < 12; ++d) {
          const double status[] = {t, double(d), 0, 0, double(c), 0, 0, 0, 0, 0};
          recorder.push(recorder.device_status_channel(), status);
        }
      }
    }
    const auto t1 = std::chrono::steady_clock::now();
    recorder.start();
    recorder.close();
    const auto t2 = std::chrono::steady_clock::now();
    push_s += std::chrono::duration<double>(t1 - t0).count();
    write_s += std::chrono::duration<double>(t2 - t1).count();
    bytes += static_cast<double>(std::filesystem::file_size(path));
    if (recorder.dropped() != 0) state.SkipWithError("a ring was full");
  }
  std::filesystem::remove(path);
  const double cycles = static_cast<double>(state.iterations()) * kCycles;
  state.counters["loop_ns_per_cycle"] = push_s / cycles * 1e9;
  state.counters["writer_us_per_cycle"] = write_s / cycles * 1e6;
  state.counters["bytes_per_cycle"] = bytes / cycles;
}
BENCHMARK(BM_RecordCycles)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
