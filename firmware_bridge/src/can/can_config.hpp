#pragma once
// Robot-file keys both CAN protocol modules share.

#include <string_view>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt::can_config {

// interface (required), bitrate, timeout_ms.
void read_common_bus(const YamlNode& node, BusConfig& bus);
// device_watchdog_ms: "off" or 0 (off), or 1..max_ms. Absent: left at the
// default, which the loader sets for the loop rate.
void read_device_watchdog(const YamlNode& node, BusConfig& bus, int max_ms);
// 1 or -1.
int read_direction(const YamlNode& node);

}  // namespace animrt::can_config
