#include "can_config.hpp"

#include <net/if.h>

#include <cmath>

#include "animrt/bridge/device_watchdog.hpp"

namespace animrt::can_config {

void read_common_bus(const YamlNode& node, BusConfig& bus) {
  const YamlNode interface = node.at("interface");
  bus.port = interface.as_string();
  if (bus.port.empty() || (bus.port.size() >= IFNAMSIZ && !bus.port.starts_with("virtual:"))) {
    interface.fail("expected a CAN interface name such as can0 (at most " +
                   std::to_string(IFNAMSIZ - 1) + " characters), found " + interface.describe());
  }
  bus.baud = 1'000'000;
  if (auto n = node.find("bitrate")) bus.baud = static_cast<int>(n->as_int_in(10'000, 1'000'000));
  bus.timeout_s = 0.004;
  if (auto n = node.find("timeout_ms")) {
    const double ms = n->as_double();
    if (!(ms > 0.0 && ms < 1000.0)) {
      n->fail("expected a number greater than 0 and less than 1000, found " + n->describe());
    }
    bus.timeout_s = ms / 1000.0;
  }
}

int read_device_watchdog(const YamlNode& node, const BusConfig& bus, int max_ms,
                         std::string_view device) {
  const int ms = static_cast<int>(
      read_device_watchdog_ms(node, bus.loop_period_s, 1.0, static_cast<double>(max_ms), device));
  const double three_periods_ms = 3.0 * bus.loop_period_s * 1000.0;
  if (ms != 0 && ms < three_periods_ms) {
    const YamlNode n = node.at(kDeviceWatchdogKey);
    n.fail("expected off or at least three loop periods (" +
           format_number(std::ceil(three_periods_ms)) + " ms at loop.rate_hz " +
           format_number(1.0 / bus.loop_period_s) + "), found " + n.describe());
  }
  return ms;
}

int read_direction(const YamlNode& node) {
  if (node.is_scalar()) {
    const std::string& s = node.raw().Scalar();
    if (s == "1" || s == "+1") return 1;
    if (s == "-1") return -1;
  }
  node.fail("expected 1 or -1 (-1 for a mirrored motor), found " + node.describe());
}

}  // namespace animrt::can_config
