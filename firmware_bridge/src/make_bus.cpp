// The factory that picks a bus implementation by protocol name.

#include <memory>
#include <string>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

std::string where(const BusConfig& config) {
  const Location& at = config.where;
  if (at.file.empty()) return "";
  std::string out = at.file;
  if (at.line > 0) out += ":" + std::to_string(at.line);
  if (at.line > 0 && at.column > 0) out += ":" + std::to_string(at.column);
  return out + ": ";
}

}  // namespace

std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) {
  if (config.protocol == "dynamixel2") {
    std::unique_ptr<ByteTransport> transport;
    try {
      transport = open_serial(config.port, config.baud);
    } catch (const DeviceError& e) {
      throw DeviceError("bus " + config.name + ": " + e.what());
    }
    return std::make_unique<DynamixelBus>(config, std::move(transport));
  }
  throw DeviceError(where(config) + "bus " + config.name + ": unknown protocol '" +
                    config.protocol + "' (known: dynamixel2)");
}

}  // namespace animrt
