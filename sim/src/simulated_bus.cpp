// Which simulated devices stand behind a bus, by its protocol.

#include "animrt/sim/simulated_bus.hpp"

#include <memory>

#include "animrt/core/error.hpp"
#include "animrt/sim/dynamixel_sim_bus.hpp"

namespace animrt {

std::unique_ptr<SimulatedBus> make_simulated_bus(const BusConfig& config, const Clock& clock) {
  if (config.protocol == "dynamixel2") return std::make_unique<sim::DynamixelSimBus>(config, clock);
  throw InputError(config.where, "protocol",
                   "no simulated devices for protocol '" + config.protocol + "' on bus '" +
                       config.name + "' (expected dynamixel2)");
}

}  // namespace animrt
