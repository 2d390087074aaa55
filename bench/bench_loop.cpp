// Loop timing and bus throughput of the 12-servo quadruped on the simulated
// Dynamixel bus (real pty, real protocol code, real-time clock).
//
//   bench_loop [seconds-per-case]
//
// Prints, per loop rate: period and wake-up jitter percentiles, overruns and
// bus I/O time; then the bus cycle rate (one Sync Write + one Sync Read of 12
// servos, back to back) against the wire limit computed from the packet
// sizes at 1 Mbaud, with the simulator emulating wire time.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

const std::string kQuadruped = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";

double ms(double s) { return s * 1e3; }
double us(double s) { return s * 1e6; }

void loop_case(double rate_hz, bool wire_time, int baud, double seconds) {
  LoadedRobot robot = load_robot(kQuadruped);
  robot.config.rate_hz = rate_hz;
  robot.config.safety.start_ramp_s = 0.5;
  robot.config.safety.stop_ramp_s = 0.5;
  for (auto& bus : robot.config.buses) {
    bus.sim.wire_time = wire_time;
    bus.baud = baud;
  }
  SimulatedBackend simulated;
  Figure figure(std::move(robot), simulated);
  RunOptions options = figure.run_options();
  options.duration_s = seconds;
  options.raise_device_threads = nullptr;  // as measured before: devices at normal priority
  RunSummary s = figure.run(options);
  std::printf(
      "%6.0f Hz  %-22s  period p50 %6.3f p99 %6.3f max %6.3f ms | jitter p50 %5.0f p99 %5.0f max "
      "%6.0f us | overruns %5llu/%-6llu | bus I/O p50 %6.3f p99 %6.3f ms | %s\n",
      rate_hz,
      wire_time ? ("wire time at " + std::to_string(baud / 1000) + " kbaud").c_str()
                : "pty speed (no wire time)",
      ms(s.period.p50_s), ms(s.period.p99_s), ms(s.period.max_s), us(s.jitter.p50_s),
      us(s.jitter.p99_s), us(s.jitter.max_s), static_cast<unsigned long long>(s.overruns),
      static_cast<unsigned long long>(s.cycles), ms(s.buses[0].io.p50_s), ms(s.buses[0].io.p99_s),
      s.sched_fifo ? "SCHED_FIFO" : "SCHED_OTHER");
}

// Bytes on the wire for one bus cycle of `servos` servos.
std::size_t cycle_bytes(std::size_t servos) {
  std::vector<std::uint8_t> ids(servos), data(servos * 4, 0), out(dxl::kMaxPacket), status(4, 0);
  for (std::size_t i = 0; i < servos; ++i) ids[i] = static_cast<std::uint8_t>(i + 1);
  const std::size_t sync_write =
      dxl::encode_sync_write(dxl::xreg::goal_position, 4, ids, data, out);
  const std::size_t sync_read = dxl::encode_sync_read(dxl::xreg::present_position, 4, ids, out);
  const std::size_t one_status = dxl::encode_status(1, 0, status, out);
  return sync_write + sync_read + servos * one_status;
}

void throughput_case(int baud, double seconds) {
  LoadedRobot robot = load_robot(kQuadruped);
  robot.config.buses[0].sim.wire_time = true;
  robot.config.buses[0].baud = baud;
  SimulatedBackend simulated;
  Figure figure(std::move(robot), simulated);  // its bus driven here, not by the loop
  const BusConfig& bus_config = figure.config().buses[0];
  MonotonicClock clock;
  ActuatorBus* bus = &figure.bus(0);
  bus->configure();
  std::vector<double> positions(bus_config.actuators.size(), 0.0);
  bus->read(positions);
  const Nanos start = clock.now();
  std::uint64_t cycles = 0;
  while (clock.now() - start < from_seconds(seconds)) {
    bus->write(positions);
    bus->read(positions);
    ++cycles;
  }
  const double achieved = static_cast<double>(cycles) / to_seconds(clock.now() - start);
  const std::size_t bytes = cycle_bytes(bus_config.actuators.size());
  const double limit = baud / 10.0 / static_cast<double>(bytes);
  std::uint64_t timeouts = 0;
  for (const auto& d : bus->devices()) timeouts += d.timeouts;
  std::printf(
      "%zu servos at %d baud: %zu bytes per cycle -> wire limit %.1f cycles/s; achieved %.1f "
      "cycles/s (%.0f %% of the limit), %llu timeouts\n",
      bus_config.actuators.size(), baud, bytes, limit, achieved, 100.0 * achieved / limit,
      static_cast<unsigned long long>(timeouts));
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  std::printf("== loop timing, 12-servo quadruped walking, %.0f s per case ==\n", seconds);
  loop_case(200, true, 1'000'000, seconds);
  loop_case(500, false, 1'000'000, seconds);
  loop_case(1000, false, 1'000'000, seconds);
  loop_case(500, true, 1'000'000, seconds);
  loop_case(500, true, 4'000'000, seconds);
  loop_case(1000, true, 4'000'000, seconds);
  std::printf("== bus cycle rate (Sync Write + Sync Read, back to back) ==\n");
  throughput_case(1'000'000, seconds);
  throughput_case(4'000'000, seconds);
  return 0;
}
