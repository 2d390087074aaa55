#include "animrt/bridge/device_watchdog.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace animrt {
namespace {

constexpr double kMinDefaultMs = 100.0;
constexpr double kDefaultPeriods = 5.0;

double round_up(double ms, double unit_ms) { return std::ceil(ms / unit_ms - 1e-9) * unit_ms; }

}  // namespace

double default_device_watchdog_ms(double loop_period_s) {
  const double periods = loop_period_s > 0.0 ? kDefaultPeriods * loop_period_s * 1000.0 : 0.0;
  return std::max(kMinDefaultMs, periods);
}

double read_device_watchdog_ms(const YamlNode& bus_node, double loop_period_s, double unit_ms,
                               double max_ms, std::string_view device) {
  const auto node = bus_node.find(kDeviceWatchdogKey);
  if (!node) return std::min(max_ms, round_up(default_device_watchdog_ms(loop_period_s), unit_ms));
  if (node->is_scalar() && node->raw().Scalar() == "off") return 0.0;
  const std::string range = format_number(unit_ms) + " to " + format_number(max_ms);
  double ms = 0.0;
  try {
    ms = node->as_double();
  } catch (const InputError&) {
    node->fail("expected off, 0, or milliseconds from " + range + " (" + std::string(device) +
               "), found " + node->describe());
  }
  if (ms == 0.0) return 0.0;
  if (!(ms >= unit_ms && ms <= max_ms)) {
    node->fail("expected off, 0, or milliseconds from " + range + " (" + std::string(device) +
               "), found " + node->describe());
  }
  return round_up(ms, unit_ms);
}

void refuse_device_watchdog(const YamlNode& bus_node, std::string_view why) {
  if (const auto node = bus_node.find(kDeviceWatchdogKey)) {
    node->fail(std::string(why) + ": remove " + std::string(kDeviceWatchdogKey));
  }
}

}  // namespace animrt
