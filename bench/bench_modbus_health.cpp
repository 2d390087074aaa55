// What reading the drives' health costs a Modbus bus cycle: four linear
// actuators (configs/modbus/linear_actuator.yaml) on four slaves of the
// simulated drives, over loopback TCP and over RTU on a pty, each cycle a
// read() and a write() back to back, with health off, packed (the health
// registers in the position's request) and round_robin (one slave's health
// registers per cycle in a request of its own). Health off runs first and
// last, so the spread between the two shows the noise.
//
//   bench_modbus_health [seconds-per-case]

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/modbus/modbus_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/sim/modbus/modbus_sim_bus.hpp"

namespace {

using namespace animrt;
using Health = ModbusBusOptions::Health;

const std::string kFigure = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml";
constexpr int kDrives = 4;

const char* name(Health h) {
  return h == Health::off ? "off" : h == Health::packed ? "packed" : "round_robin";
}

// The animatronic's torso bus with its drive repeated on slaves 1..kDrives.
BusConfig four_drives(bool tcp, Health health) {
  const RobotConfig robot = load_robot_config(kFigure);
  BusConfig bus;
  for (const BusConfig& b : robot.buses) {
    if (b.name == "torso") bus = b;
  }
  const ActuatorBinding one = bus.actuators.front();
  bus.actuators.clear();
  for (int k = 1; k <= kDrives; ++k) {
    ActuatorBinding a = one;
    auto o = std::any_cast<ModbusJointOptions>(a.options);
    o.slave = k;
    a.options = o;
    a.device_id = k;
    a.joint = "drive" + std::to_string(k);
    bus.actuators.push_back(a);
  }
  auto o = std::any_cast<ModbusBusOptions>(bus.options);
  o.tcp = tcp;
  o.health = health;
  bus.options = o;
  bus.protocol = tcp ? "modbus-tcp" : "modbus-rtu";
  bus.baud = 115200;
  bus.timeout_s = 0.05;
  return bus;
}

void run_case(bool tcp, Health health, double seconds) {
  MonotonicClock clock;
  BusConfig config = four_drives(tcp, health);
  sim::ModbusSimBus sim(config, clock);
  sim.start();
  config.port = sim.endpoint();
  ModbusBus bus(config);
  bus.configure();
  bus.activate();
  std::vector<double> pos(kDrives), goal(kDrives, 0.0);
  using steady = std::chrono::steady_clock;
  const auto t0 = steady::now();
  const std::uint64_t r0 = bus.requests();
  std::uint64_t cycles = 0;
  while (steady::now() - t0 < std::chrono::duration<double>(seconds)) {
    bus.read(pos);
    bus.write(goal);
    ++cycles;
  }
  const double dt = std::chrono::duration<double>(steady::now() - t0).count();
  const double per_drive =
      static_cast<double>(bus.devices()[0].reading.reads) / static_cast<double>(cycles);
  std::printf(
      "%-4s health %-11s %7.0f cycles/s  %6.1f us/cycle  %4.2f requests/cycle  "
      "%4.2f health readings per drive and cycle\n",
      tcp ? "TCP" : "RTU", name(health), static_cast<double>(cycles) / dt,
      dt / static_cast<double>(cycles) * 1e6,
      static_cast<double>(bus.requests() - r0) / static_cast<double>(cycles), per_drive);
  bus.deactivate();
  sim.stop();
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 3.0;
  std::printf("Modbus bus cycle (read + write), %d drives on %d slaves, simulated, real time\n",
              kDrives, kDrives);
  for (bool tcp : {true, false}) {
    for (Health h : {Health::off, Health::packed, Health::round_robin, Health::off})
      run_case(tcp, h, seconds);
  }
  return 0;
}
