#include "animrt/bridge/serial_servo/servo_link.hpp"

#include <cmath>
#include <cstdio>

#include "animrt/core/error.hpp"

namespace animrt::servo {

void check_bindings(const BusConfig& config, int max_id, std::size_t max_devices) {
  const std::string bus = "bus " + config.name + ": ";
  const std::size_t n = config.actuators.size();
  if (n > max_devices) {
    throw DeviceError(bus + std::to_string(n) + " devices do not fit one Sync Write (at most " +
                      std::to_string(max_devices) + ")");
  }
  bool used[256] = {};
  for (const ActuatorBinding& b : config.actuators) {
    const std::string who = "device id " + std::to_string(b.device_id) + " (" + b.joint + ")";
    if (b.device_id < 0 || b.device_id > max_id) {
      throw DeviceError(bus + who + " is outside 0.." + std::to_string(max_id));
    }
    if (used[b.device_id]) throw DeviceError(bus + who + " is used twice");
    used[b.device_id] = true;
    if (b.direction != 1 && b.direction != -1) {
      throw DeviceError(bus + who + ": direction must be +1 or -1");
    }
    if (!(b.ticks_per_rad > 0.0) || !std::isfinite(b.ticks_per_rad)) {
      throw DeviceError(bus + who + ": ticks per radian must be positive");
    }
  }
}

std::string hex_byte(std::uint8_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v);
  return buf;
}

std::string fault_text(const char* what, std::uint8_t bits, std::span<const FaultBit> names) {
  std::string out = std::string(what) + " " + hex_byte(bits);
  std::string set;
  for (const FaultBit& f : names) {
    if ((bits & f.bit) != 0) set += (set.empty() ? "" : ", ") + std::string(f.name);
  }
  return set.empty() ? out : out + ": " + set;
}

void throw_unanswered(const StatusBook& book, const ByteTransport& transport,
                      const std::vector<bool>& answered, const std::vector<bool>& garbled) {
  const std::string silent = book.list([&](std::size_t i) { return !answered[i] && !garbled[i]; });
  const std::string bad = book.list([&](std::size_t i) { return !answered[i] && garbled[i]; });
  if (transport.failure() != nullptr)
    throw DeviceError(book.prefix() + describe_failure(transport));
  if (silent.empty() && bad.empty()) return;
  std::string message = book.prefix();
  if (!silent.empty()) message += "no answer to ping from " + silent;
  if (!bad.empty())
    message += (silent.empty() ? "" : "; ") + std::string("garbled answer to ping from ") + bad;
  throw DeviceError(message);
}

}  // namespace animrt::servo
