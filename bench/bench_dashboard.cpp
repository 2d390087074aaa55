// The loop with and without the dashboard: the 12-servo quadruped walking
// at 200 Hz on the simulated Dynamixel bus (wire time emulated), alone and
// with a dashboard whose stream a client reads at 30 Hz, alternating in the
// same process so both see the same machine.
//
//   bench_dashboard [seconds-per-run] [rounds]
//
// Prints per run: period, jitter and work-per-cycle percentiles, overruns,
// late bus cycles, and for the dashboard runs the frames the client got.

#include <httplib.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "animrt/core/clock.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

const std::string kQuadruped = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";

double ms(double s) { return s * 1e3; }

void run_case(bool dashboard, double seconds) {
  LoadedRobot robot = load_robot(kQuadruped);
  robot.config.safety.start_ramp_s = 0.5;
  robot.config.safety.stop_ramp_s = 0.5;
  SimulatedBackend simulated;
  Figure figure(std::move(robot), simulated);
  RunControls controls;
  RunOptions options = figure.run_options();
  options.duration_s = seconds;
  options.controls = &controls;
  options.raise_device_threads = nullptr;  // as measured before: devices at normal priority

  // Stops the stream and joins its client however the run ends.
  struct Dashboard {
    DashboardServer* server = nullptr;
    std::thread client;
    std::atomic<bool> quit{false};
    std::atomic<int> frames{0};
    ~Dashboard() {
      quit = true;
      if (server) server->stop();
      if (client.joinable()) client.join();
    }
  } d;
  if (dashboard) {
    DashboardSetup setup;
    setup.steering = figure.steering();
    d.server = &figure.serve_dashboard(setup, controls);
    d.client = std::thread([&d] {
      httplib::Client c("127.0.0.1", d.server->port());
      c.Get("/api/stream", [&d](const char* data, std::size_t length) {
        for (std::size_t i = 0; i + 1 < length; ++i) {
          if (data[i] == '\n' && data[i + 1] == '\n') ++d.frames;
        }
        return !d.quit.load();
      });
    });
  }
  RunSummary s = figure.run(options);
  std::printf(
      "%-14s period p50 %6.3f p99 %6.3f max %6.3f ms | jitter p50 %6.3f p99 %6.3f max %6.3f ms | "
      "work p50 %6.3f p99 %6.3f max %6.3f ms | overruns %3llu/%-5llu late %3llu | ended by %s | %s",
      dashboard ? "dashboard" : "alone", ms(s.period.p50_s), ms(s.period.p99_s), ms(s.period.max_s),
      ms(s.jitter.p50_s), ms(s.jitter.p99_s), ms(s.jitter.max_s), ms(s.busy.p50_s),
      ms(s.busy.p99_s), ms(s.busy.max_s), static_cast<unsigned long long>(s.overruns),
      static_cast<unsigned long long>(s.cycles),
      static_cast<unsigned long long>(s.buses[0].late_cycles), to_string(s.end_reason),
      s.sched_fifo ? "SCHED_FIFO" : "SCHED_OTHER");
  if (dashboard) std::printf(" | %d frames streamed", d.frames.load());
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 2;
  std::printf("== 12-servo quadruped at 200 Hz, %.0f s of motion per run, a 30 Hz stream ==\n",
              seconds);
  // A busy machine can make a simulated servo miss a ping at bring-up;
  // that run is tried again (the loop's figures are what is measured).
  const auto attempt = [seconds](bool dashboard) {
    for (int tries = 0;; ++tries) {
      try {
        run_case(dashboard, seconds);
        return;
      } catch (const DeviceError& e) {
        std::printf("bring-up failed (%s)%s\n", e.what(), tries < 4 ? "; again" : "");
        if (tries >= 4) return;
      }
    }
  };
  for (int r = 0; r < rounds; ++r) {
    attempt(false);
    attempt(true);
  }
  return 0;
}
