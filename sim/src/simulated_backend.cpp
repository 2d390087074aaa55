#include "animrt/sim/simulated_backend.hpp"

#include <algorithm>

namespace animrt {

std::vector<std::unique_ptr<SimulatedBus>> start_simulated_devices(std::vector<BusConfig>& buses,
                                                                   const Clock& clock,
                                                                   sim::JointPhysics* physics) {
  std::vector<std::unique_ptr<SimulatedBus>> simulated;
  for (auto& bus : buses) {
    auto sim = make_simulated_bus(bus, clock, physics);
    sim->start();
    bus.port = sim->endpoint();
    simulated.push_back(std::move(sim));
  }
  return simulated;
}

std::vector<std::string> raise_simulated_devices(
    const std::vector<std::unique_ptr<SimulatedBus>>& simulated, int priority) {
  std::vector<std::string> notes;
  for (const auto& bus : simulated) {
    if (std::string why = bus->raise_priority(priority); !why.empty()) {
      notes.push_back(bus->describe() + ": " + why + ", normal thread");
    }
  }
  return notes;
}

void widen_timeouts_for_lockstep(std::vector<BusConfig>& buses) {
  for (BusConfig& bus : buses) bus.timeout_s = std::max(bus.timeout_s, kLockstepMinTimeoutS);
}

}  // namespace animrt
