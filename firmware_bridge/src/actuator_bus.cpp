#include "animrt/bridge/actuator_bus.hpp"

#include <chrono>
#include <thread>

#include "animrt/core/error.hpp"

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

std::vector<bool> ping_until_answered(std::size_t devices,
                                      const std::function<bool(std::size_t)>& ping) {
  std::vector<bool> answered(devices, false);
  for (int round = 0; round < kPingRounds; ++round) {
    if (round > 0) std::this_thread::sleep_for(std::chrono::milliseconds(kPingPauseMs));
    bool all = true;
    for (std::size_t i = 0; i < devices; ++i) {
      if (!answered[i]) answered[i] = ping(i);
      all = all && answered[i];
    }
    if (all) break;
  }
  return answered;
}

std::int64_t ActuatorBus::set_home(std::size_t device, std::int64_t ticks) {
  (void)ticks;
  const std::string joint =
      device < config().actuators.size() ? config().actuators[device].joint : "?";
  throw DeviceError("bus " + config().name + ": joint " + joint +
                    ": its device cannot be homed by animrt on this bus");
}

}  // namespace animrt
