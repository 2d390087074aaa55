// Bus cycle rate of 12 simulated Dynamixel servos (the quadruped's bus):
// one Sync Write of the goals plus one read of the present positions, back
// to back, with the read a plain Sync Read or a Fast Sync Read, in the same
// run, at 1 and 4 Mbaud.
//
//   bench_dynamixel [seconds-per-case]
//
// A pty moves bytes as fast as the kernel copies them, so the simulator
// emulates the wire (sim.wire_time): each answer leaves when the
// instruction's and the answers' bytes would have passed at 10 bits per byte
// at the baud rate. The wire limit printed beside each figure is that same
// arithmetic for one cycle's bytes; "achieved" is what the real bus code,
// pty and simulator threads reach against it on this machine. A last pair
// of cases without wire time shows what the processing alone allows.

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/bridge/dynamixel/dynamixel_protocol.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
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
  std::size_t bytes = 0;
  std::uint64_t timeouts = 0;
  bool fast = false;
};

Result run(int baud, bool fast, double seconds, bool wire_time = true) {
  LoadedRobot robot = load_robot(kQuadruped);
  BusConfig& config = robot.config.buses[0];
  config.sim.wire_time = wire_time;
  config.sim.firmware_version = 46;  // X430 fast read needs 45 or later
  config.timeout_s = 0.05;           // a loaded machine must not turn into timeouts
  config.baud = baud;
  dxl::BusOptions options = dxl::bus_options(config);
  options.fast_read = fast ? dxl::FastRead::on : dxl::FastRead::off;
  config.options = options;
  const std::size_t servos = config.actuators.size();
  SimulatedBackend simulated;
  Figure figure(std::move(robot), simulated);  // its bus driven here, not by the loop
  MonotonicClock clock;
  ActuatorBus* bus = &figure.bus(0);
  bus->configure();
  std::vector<double> positions(servos, 0.0);
  bus->read(positions);
  const Nanos start = clock.now();
  std::uint64_t cycles = 0;
  while (clock.now() - start < from_seconds(seconds)) {
    bus->write(positions);
    bus->read(positions);
    ++cycles;
  }
  Result r;
  r.achieved = static_cast<double>(cycles) / to_seconds(clock.now() - start);
  r.bytes = dynamixel_wire_bytes(servos, fast);
  r.limit = baud / 10.0 / static_cast<double>(r.bytes);
  for (const auto& d : bus->devices()) r.timeouts += d.timeouts;
  if (auto* dxl_bus = dynamic_cast<DynamixelBus*>(bus)) r.fast = dxl_bus->fast_read_active();
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  std::printf("== 12 servos: Sync Write + read, back to back, wire time emulated, %.0f s each ==\n",
              seconds);
  for (int baud : {1'000'000, 4'000'000}) {
    const Result plain = run(baud, false, seconds);
    const Result fast = run(baud, true, seconds);
    for (const Result* r : {&plain, &fast}) {
      std::printf(
          "%d baud, %-14s: %3zu bytes per cycle -> wire limit %6.1f cycles/s; achieved %6.1f "
          "cycles/s (%3.0f %% of the limit), %llu timeouts\n",
          baud, r->fast ? "Fast Sync Read" : "Sync Read", r->bytes, r->limit, r->achieved,
          100.0 * r->achieved / r->limit, static_cast<unsigned long long>(r->timeouts));
    }
    std::printf("%d baud: Fast Sync Read / Sync Read = %.2f (wire limits: %.2f)\n", baud,
                fast.achieved / plain.achieved, fast.limit / plain.limit);
  }
  // Without wire time the pty carries bytes as fast as the threads run: what
  // one cycle costs in processing alone (no wire limit applies).
  const Result plain = run(1'000'000, false, seconds, false);
  const Result fast = run(1'000'000, true, seconds, false);
  std::printf("no wire time (pty speed): Sync Read %.0f cycles/s, Fast Sync Read %.0f cycles/s\n",
              plain.achieved, fast.achieved);
  return 0;
}
