// The mixed-bus animatronic figure (Dynamixel neck, Maestro face, Modbus TCP
// torso) on simulated devices in real time, and Modbus TCP round trips
// against the simulated drive.
//
//   bench_mixed [seconds-per-case]
//
// Prints, per loop rate: the loop's period, jitter and overruns, and per bus
// its cycle time (read + write on its own I/O thread) and late cycles; then
// the same with the Modbus drive answering 25 ms late (a slow bus); then
// Modbus TCP request rates: one Read Holding Registers round trip, and a
// full bus cycle (read + write) of the torso bus.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "animrt/bridge/modbus/modbus_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

const std::string kFigure = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml";

double ms(double s) { return s * 1e3; }

void loop_case(double rate_hz, int torso_delay_us, double seconds) {
  LoadedRobot robot = load_robot(kFigure);
  robot.config.rate_hz = rate_hz;
  robot.config.safety.start_ramp_s = 0.5;
  robot.config.safety.stop_ramp_s = 0.5;
  for (auto& bus : robot.config.buses) {
    if (bus.name == "torso") {
      bus.sim.return_delay_us = torso_delay_us;
      bus.timeout_s = 0.2;
    }
  }
  SimulatedBackend simulated;
  Figure figure(std::move(robot), simulated);
  RunOptions options = figure.run_options();
  options.duration_s = seconds;
  options.raise_device_threads = nullptr;  // as measured before: devices at normal priority
  const RunSummary s = figure.run(options);
  std::printf(
      "%5.0f Hz, torso answer delay %2d ms: cycles %llu, overruns %llu, period p99 %.3f ms, jitter "
      "p99 %.3f ms%s\n",
      rate_hz, torso_delay_us / 1000, static_cast<unsigned long long>(s.cycles),
      static_cast<unsigned long long>(s.overruns), ms(s.period.p99_s), ms(s.jitter.p99_s),
      s.sched_fifo ? " (SCHED_FIFO)" : "");
  for (const auto& b : s.buses) {
    std::printf(
        "        bus %-6s cycle time p50 %.3f ms, p99 %.3f ms, max %.3f ms; late cycles %llu\n",
        b.name.c_str(), ms(b.io.p50_s), ms(b.io.p99_s), ms(b.io.max_s),
        static_cast<unsigned long long>(b.late_cycles));
  }
}

void modbus_case(double seconds) {
  SimulatedBackend simulated;
  Figure figure(load_robot(kFigure), simulated);  // its torso bus driven here, not by the loop
  std::size_t torso = 0;
  while (figure.config().buses[torso].name != "torso") ++torso;
  ModbusBus& bus = dynamic_cast<ModbusBus&>(figure.bus(torso));
  bus.configure();
  bus.activate();
  std::vector<double> pos(1), goal(1, 0.0);
  using steady = std::chrono::steady_clock;
  // Read only: one Read Holding Registers (present + status) per call.
  auto t0 = steady::now();
  std::uint64_t r0 = bus.requests();
  while (steady::now() - t0 < std::chrono::duration<double>(seconds)) bus.read(pos);
  double dt = std::chrono::duration<double>(steady::now() - t0).count();
  const double reads = static_cast<double>(bus.requests() - r0) / dt;
  // Full cycles: read + Write Multiple Registers.
  t0 = steady::now();
  r0 = bus.requests();
  std::uint64_t cycles = 0;
  while (steady::now() - t0 < std::chrono::duration<double>(seconds)) {
    bus.read(pos);
    bus.write(goal);
    ++cycles;
  }
  dt = std::chrono::duration<double>(steady::now() - t0).count();
  std::printf(
      "Modbus TCP (loopback, simulated drive): %.0f round trips/s (Read Holding Registers), "
      "%.0f bus cycles/s (read + write, %.0f requests/s)\n",
      reads, static_cast<double>(cycles) / dt, static_cast<double>(bus.requests() - r0) / dt);
  bus.deactivate();
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  std::printf(
      "mixed figure: Dynamixel neck (2), Maestro face (3), Modbus TCP torso (1), simulated, real "
      "time\n");
  loop_case(100.0, 0, seconds);
  loop_case(200.0, 0, seconds);
  loop_case(100.0, 25000, seconds);
  modbus_case(seconds > 3 ? 3.0 : seconds);
  return 0;
}
