// Time from the host's death to every CAN device of the CAN quadruped
// stopped by its own guard, on the wall clock: the runtime's buses cycle at
// the robot's loop rate for a second of motion, then stop dead (no
// deactivate, no further frame). A client of its own asks the CiA 402 drive
// for its statusword (SDO upload) every 0.2 ms until it has left Operation
// Enabled; the simulated MIT motors are watched from their side until every
// one has gone limp. Death = the moment the last cycle's frames were sent.
//
// Usage: bench_can_host_death [TRIALS]   (default 20)

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";
constexpr canid_t kDrive = 32;
constexpr int kLeft[] = {1, 2, 3, 4, 5, 6};
constexpr int kRight[] = {7, 8, 9, 11, 12};

// Statusword of node 32 by expedited SDO upload; -1 without an answer.
int statusword(CanFrameTransport& client) {
  can_frame f;
  while (client.receive(f, std::chrono::microseconds(0))) {
  }
  can_frame request{};
  request.can_id = 0x600 + kDrive;
  request.len = 8;
  request.data[0] = 0x40;
  request.data[1] = 0x41;
  request.data[2] = 0x60;
  client.send(request);
  while (client.receive(f, std::chrono::milliseconds(100))) {
    if (f.can_id == 0x580 + kDrive && f.data[1] == 0x41 && f.data[2] == 0x60)
      return f.data[4] | (f.data[5] << 8);
  }
  return -1;
}

struct Trial {
  double drive_ms = -1, motors_ms = -1;
};

Trial run_trial() {
  LoadedRobot robot = load_robot(kRobot);
  for (BusConfig& bus : robot.config.buses) bus.timeout_s = std::max(bus.timeout_s, 0.02);
  // The figure's buses are driven here, by hand, so that the host can die
  // between two cycles; the loop never runs.
  SimulatedBackend simulated;
  auto figure = std::make_unique<Figure>(std::move(robot), simulated);
  const RobotConfig& config = figure->config();
  auto& left = dynamic_cast<sim::CanSimBus&>(*simulated.devices()[0]);
  auto& right = dynamic_cast<sim::CanSimBus&>(*simulated.devices()[1]);
  auto client = VirtualCanBus::named("can1")->attach();
  const can_filter filter{0x580 + kDrive, CAN_SFF_MASK};
  client->set_filters(std::span<const can_filter>(&filter, 1));

  std::vector<ActuatorBus*> buses;
  std::vector<std::vector<double>> start, q;
  for (std::size_t b = 0; b < figure->bus_count(); ++b) buses.push_back(&figure->bus(b));
  for (auto* bus : buses) {
    bus->configure();
    start.emplace_back(bus->config().actuators.size(), 0.0);
    bus->read(start.back());
  }
  q = start;
  for (auto* bus : buses) bus->activate();
  for (auto* bus : buses) bus->arm_device_guard();
  const auto period = std::chrono::nanoseconds(static_cast<long>(1e9 / config.rate_hz));
  auto deadline = std::chrono::steady_clock::now();
  const int cycles = static_cast<int>(config.rate_hz);
  for (int k = 0; k < cycles; ++k) {
    deadline += period;
    std::this_thread::sleep_until(deadline);
    for (std::size_t b = 0; b < buses.size(); ++b) buses[b]->read(q[b]);
    const double s = 0.2 * std::sin(2.0 * 3.141592653589793 * k / cycles);
    for (std::size_t b = 0; b < buses.size(); ++b) {
      for (std::size_t d = 0; d < q[b].size(); ++d) q[b][d] = start[b][d] + s;
      buses[b]->write(q[b]);
    }
  }
  const auto death = std::chrono::steady_clock::now();
  Trial t;
  const auto since = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - death)
        .count();
  };
  while (since() < 1000.0 && (t.drive_ms < 0 || t.motors_ms < 0)) {
    if (t.drive_ms < 0) {
      const int sw = statusword(*client);
      if (sw >= 0 && (sw & 0x6F) != 0x27) t.drive_ms = since();
    }
    if (t.motors_ms < 0) {
      bool all = true;
      for (int id : kLeft) all = all && left.device_guard_fired(id);
      for (int id : kRight) all = all && right.device_guard_fired(id);
      if (all) t.motors_ms = since();
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  buses.clear();
  figure.reset();  // dead: the buses close, never deactivated; then the devices stop
  client.reset();
  return t;
}

void report(const char* what, std::vector<double> v) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return;
  std::printf("%-40s min %6.1f  median %6.1f  max %6.1f ms  (%zu trials)\n", what, v.front(),
              v[v.size() / 2], v.back(), v.size());
}

}  // namespace

int main(int argc, char** argv) {
  const int trials = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20;
  std::vector<double> drive, motors;
  int missed = 0;
  for (int i = 0; i < trials; ++i) {
    const Trial t = run_trial();
    std::printf(
        "trial %2d: drive out of Operation Enabled %6.1f ms, every MIT motor limp %6.1f ms\n",
        i + 1, t.drive_ms, t.motors_ms);
    if (t.drive_ms < 0 || t.motors_ms < 0) ++missed;
    if (t.drive_ms >= 0) drive.push_back(t.drive_ms);
    if (t.motors_ms >= 0) motors.push_back(t.motors_ms);
  }
  std::printf(
      "device_watchdog_ms 50 (quadruped_can.yaml), loop 200 Hz, host heartbeat every 12 ms\n");
  report("death -> drive out of Operation Enabled", drive);
  report("death -> every MIT motor limp", motors);
  std::printf("trials where a device did not stop within 1 s: %d\n", missed);
  return missed == 0 ? 0 : 1;
}
