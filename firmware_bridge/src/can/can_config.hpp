#pragma once
// Robot-file keys both CAN protocol modules share.

#include <string_view>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt::can_config {

// interface (required), bitrate, timeout_ms.
void read_common_bus(const YamlNode& node, BusConfig& bus);
// device_watchdog_ms in whole milliseconds (0: off; absent: the default for
// the loop rate), at most max_ms, and when set at least three loop periods:
// the host's cycle is what feeds the devices' guard.
int read_device_watchdog(const YamlNode& node, const BusConfig& bus, int max_ms,
                         std::string_view device);
// 1 or -1.
int read_direction(const YamlNode& node);

}  // namespace animrt::can_config
