// Which simulated devices stand behind a bus, by its protocol.

#include "animrt/sim/simulated_bus.hpp"

#include <memory>

#include "animrt/bridge/feetech/feetech_protocol.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/dynamixel_sim_bus.hpp"
#include "animrt/sim/feetech/feetech_sim_bus.hpp"
#include "animrt/sim/maestro/maestro_sim_bus.hpp"
#include "animrt/sim/modbus/modbus_sim_bus.hpp"

namespace animrt {

std::unique_ptr<SimulatedBus> make_simulated_bus(const BusConfig& config, const Clock& clock,
                                                 sim::JointPhysics* physics,
                                                 const ServoStartup& startup) {
  if (config.protocol == "dynamixel2") {
    return std::make_unique<sim::DynamixelSimBus>(config, clock, physics, startup);
  }
  if (physics != nullptr) {
    throw InputError(config.where, "protocol",
                     "physics drives only dynamixel2 buses; bus '" + elide(config.name) + "' is " +
                         config.protocol);
  }
  if (ft::Series series; feetech_series(config.protocol, series)) {
    return std::make_unique<sim::FeetechSimBus>(config, series, clock, startup);
  }
  if (config.protocol == "mit" || config.protocol == "cia402")
    return sim::make_can_sim_bus(config, clock);
  if (config.protocol == "maestro") return std::make_unique<sim::MaestroSimBus>(config, clock);
  if (config.protocol == "modbus-tcp" || config.protocol == "modbus-rtu") {
    return std::make_unique<sim::ModbusSimBus>(config, clock);
  }
  throw InputError(config.where, "protocol",
                   "no simulated devices for protocol '" + elide(config.protocol) + "' on bus '" +
                       elide(config.name) +
                       "' (expected dynamixel2, feetech_sts, feetech_scs, mit, cia402, maestro, "
                       "modbus-tcp or modbus-rtu)");
}

}  // namespace animrt
