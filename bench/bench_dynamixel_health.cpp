// Bus cycle rate of 12 simulated Dynamixel servos (the quadruped's bus)
// with device health read: positions only, health packed into the cycle's
// Fast Sync Read (Indirect Data: position, current, voltage, temperature,
// hardware error = 10 bytes per servo instead of 4), or health read one
// servo per cycle in a Read of its own (round robin). One Sync Write of the
// goals plus the read(s), back to back, at 1 and 4 Mbaud, wire time
// emulated as in bench_dynamixel.
//
//   bench_dynamixel_health [seconds-per-case]

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/bridge/protocol.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

const std::string kQuadruped = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";

struct Result {
  double achieved = 0.0;
  double limit = 0.0;
  std::uint64_t timeouts = 0;
  std::uint64_t health_reads = 0;  // per servo, over the run (the fewest)
  std::uint64_t cycles = 0;
};

const char* name(dxl::HealthRead how) {
  switch (how) {
    case dxl::HealthRead::off:
      return "positions only";
    case dxl::HealthRead::packed:
      return "health packed";
    case dxl::HealthRead::round_robin:
      return "round robin";
  }
  return "?";
}

Result run(int baud, dxl::HealthRead how, double seconds) {
  LoadedRobot robot = load_robot(kQuadruped);
  BusConfig& config = robot.config.buses[0];
  config.sim.wire_time = true;
  config.sim.firmware_version = 46;  // X430 fast read needs 45 or later
  config.timeout_s = 0.05;           // a loaded machine must not turn into timeouts
  config.baud = baud;
  dxl::BusOptions options = dxl::bus_options(config);
  options.fast_read = dxl::FastRead::on;
  options.health = how;
  config.options = options;
  const Protocol* protocol = find_protocol(config.protocol);
  const double bits = protocol->wire_bits_per_cycle(config);
  const std::size_t servos = config.actuators.size();
  SimulatedBackend simulated;
  Figure figure(std::move(robot), simulated);
  MonotonicClock clock;
  ActuatorBus* bus = &figure.bus(0);
  bus->configure();
  std::vector<double> positions(servos, 0.0);
  bus->read(positions);
  const Nanos start = clock.now();
  Result r;
  while (clock.now() - start < from_seconds(seconds)) {
    bus->write(positions);
    bus->read(positions);
    ++r.cycles;
  }
  r.achieved = static_cast<double>(r.cycles) / to_seconds(clock.now() - start);
  r.limit = baud / bits;
  r.health_reads = ~std::uint64_t{0};
  for (const auto& d : bus->devices()) {
    r.timeouts += d.timeouts;
    r.health_reads = std::min(r.health_reads, d.reading.reads);
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  std::printf(
      "== 12 servos, Fast Sync Read: Sync Write + read(s), back to back, wire time emulated, "
      "%.0f s each ==\n",
      seconds);
  // Positions only both first and last at each baud: on a loaded machine
  // the spread between the two is the noise of the figures.
  for (int baud : {1'000'000, 4'000'000}) {
    const dxl::HealthRead kinds[] = {dxl::HealthRead::off, dxl::HealthRead::packed,
                                     dxl::HealthRead::round_robin, dxl::HealthRead::off};
    Result results[4];
    for (int k = 0; k < 4; ++k) {
      const Result& r = results[k] = run(baud, kinds[k], seconds);
      const double per_servo_hz = r.cycles ? r.achieved * static_cast<double>(r.health_reads) /
                                                 static_cast<double>(r.cycles)
                                           : 0.0;
      std::printf(
          "%d baud, %-14s: wire limit %6.1f cycles/s; achieved %6.1f cycles/s (%3.0f %%), "
          "health of each servo at %6.1f Hz, %llu timeouts\n",
          baud, name(kinds[k]), r.limit, r.achieved, 100.0 * r.achieved / r.limit, per_servo_hz,
          static_cast<unsigned long long>(r.timeouts));
    }
    const double plain = 0.5 * (results[0].achieved + results[3].achieved);
    std::printf("%d baud: packed / positions only = %.2f, round robin / positions only = %.2f\n",
                baud, results[1].achieved / plain, results[2].achieved / plain);
  }
  return 0;
}
