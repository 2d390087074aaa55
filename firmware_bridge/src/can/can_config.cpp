#include "can_config.hpp"

#include <net/if.h>

#include <charconv>

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

void read_device_watchdog(const YamlNode& node, BusConfig& bus, int max_ms) {
  const auto n = node.find("device_watchdog_ms");
  if (!n) return;
  if (n->is_scalar() && (n->raw().Scalar() == "off" || n->raw().Scalar() == "0")) {
    bus.device_watchdog_ms = 0;
    return;
  }
  const std::string expected =
      "expected off, 0 (off) or milliseconds from 1 to " + std::to_string(max_ms);
  std::int64_t ms = 0;
  if (n->is_scalar()) {
    const std::string& s = n->raw().Scalar();
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), ms);
    if (ec != std::errc() || end != s.data() + s.size()) ms = -1;
  }
  if (!n->is_scalar() || ms < 1 || ms > max_ms) n->fail(expected + ", found " + n->describe());
  bus.device_watchdog_ms = static_cast<int>(ms);
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
