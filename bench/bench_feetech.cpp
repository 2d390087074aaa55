// Feetech bus cycle rate against its wire limit: one Sync Write of the goals
// and one read of the present positions (STS: a Sync Read; SCS: one Read per
// servo), back to back, for 6 and 12 servos at 1 Mbaud, with the simulated
// servo board emulating wire time (10 bits per byte at the baud rate, return
// delay 0). The wire limit is computed from the packets the codec encodes.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt {
namespace {

std::size_t cycle_bytes(ft::Series series, std::size_t servos) {
  std::vector<std::uint8_t> ids(servos), data(servos * 2, 0), out(ft::kMaxPacket), pos(2, 0);
  for (std::size_t i = 0; i < servos; ++i) ids[i] = static_cast<std::uint8_t>(i + 1);
  const std::size_t write = ft::encode_sync_write(ft::reg::goal_position, 2, ids, data, out);
  const std::size_t status = ft::encode_status(1, 0, pos, out);
  if (series == ft::Series::sts) {
    return write + ft::encode_sync_read(ft::reg::present_position, 2, ids, out) + servos * status;
  }
  return write + servos * (ft::encode_read(1, ft::reg::present_position, 2, out) + status);
}

void throughput_case(ft::Series series, std::size_t servos, int baud, double seconds) {
  BusConfig config;
  config.name = "arm";
  config.protocol = series == ft::Series::sts ? "feetech_sts" : "feetech_scs";
  config.baud = baud;
  config.timeout_s = 0.05;
  config.sim.wire_time = true;
  for (std::size_t i = 0; i < servos; ++i) {
    ActuatorBinding b;
    b.joint = "j" + std::to_string(i + 1);
    b.joint_index = static_cast<int>(i);
    b.device_id = static_cast<int>(i + 1);
    b.ticks_per_rad =
        (series == ft::Series::sts ? ft::kStsStepsPerRev : ft::kScsStepsPerRev) / (2 * 3.14159265);
    b.zero_ticks = series == ft::Series::sts ? 2048 : 512;
    config.actuators.push_back(b);
  }
  MonotonicClock clock;
  auto sim = make_simulated_bus(config, clock);
  sim->start();
  config.port = sim->endpoint();
  auto bus = make_bus(config);
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
  const double achieved = static_cast<double>(cycles) / to_seconds(clock.now() - start);
  const std::size_t bytes = cycle_bytes(series, servos);
  const double limit = baud / 10.0 / static_cast<double>(bytes);
  std::uint64_t timeouts = 0;
  for (const auto& d : bus->devices()) timeouts += d.timeouts;
  std::printf(
      "%s, %zu servos at %d baud: %zu bytes per cycle -> wire limit %.1f cycles/s; achieved "
      "%.1f cycles/s (%.0f %% of the limit), %llu timeouts\n",
      config.protocol.c_str(), servos, baud, bytes, limit, achieved, 100.0 * achieved / limit,
      static_cast<unsigned long long>(timeouts));
}

}  // namespace
}  // namespace animrt

int main(int argc, char** argv) {
  using namespace animrt;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  std::printf("== Feetech bus cycle rate (Sync Write + read, back to back, %.0f s per case) ==\n",
              seconds);
  for (ft::Series series : {ft::Series::sts, ft::Series::scs}) {
    for (std::size_t servos : {6u, 12u}) throughput_case(series, servos, 1'000'000, seconds);
  }
  return 0;
}
