#include "animrt/bridge/actuator_bus.hpp"

namespace animrt {

const char* to_string(DeviceHealth health) {
  switch (health) {
    case DeviceHealth::ok:
      return "ok";
    case DeviceHealth::timeout:
      return "timeout";
    case DeviceHealth::protocol_error:
      return "protocol_error";
    case DeviceHealth::hardware_error:
      return "hardware_error";
  }
  return "unknown";
}

}  // namespace animrt
