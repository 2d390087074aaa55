// The protocol registry and the bus factory.

#include <memory>
#include <string>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/can/can_protocols.hpp"
#include "animrt/bridge/dynamixel/dynamixel_protocol.hpp"
#include "animrt/bridge/feetech/feetech_protocol.hpp"
#include "animrt/bridge/maestro/maestro_protocol.hpp"
#include "animrt/bridge/modbus/modbus_protocol.hpp"
#include "animrt/bridge/protocol.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

// Every protocol the runtime can drive. Add a module here to add a device.
const Protocol* const kProtocols[] = {
    &dynamixel2_protocol(),  &mit_protocol(),         &cia402_protocol(),
    &maestro_protocol(),     &modbus_tcp_protocol(),  &modbus_rtu_protocol(),
    &feetech_sts_protocol(), &feetech_scs_protocol(),
};

}  // namespace

const Protocol* find_protocol(std::string_view name) {
  for (const Protocol* p : kProtocols) {
    if (p->name() == name) return p;
  }
  return nullptr;
}

std::string supported_protocols() {
  std::string out;
  for (const Protocol* p : kProtocols) out += (out.empty() ? "" : ", ") + std::string(p->name());
  return out;
}

std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) {
  if (const Protocol* protocol = find_protocol(config.protocol)) return protocol->make_bus(config);
  throw DeviceError("bus " + config.name + ": unknown protocol '" + elide(config.protocol) +
                    "' (supported: " + supported_protocols() + ")");
}

}  // namespace animrt
