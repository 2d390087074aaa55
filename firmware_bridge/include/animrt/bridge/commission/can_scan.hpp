#pragma once
// CANopen nodes on a CAN interface, found without changing any state: the
// heartbeats they send anyway, then an SDO read (upload) of Device Type
// (0x1000) and Identity (0x1018: vendor, product, revision) of each node
// id asked. NMT is never sent. MIT-mode motors have no query that leaves
// them passive (every command frame sets a torque), so they are not asked.

#include <chrono>
#include <string>

#include "animrt/bridge/commission/found_device.hpp"

namespace animrt::commission {

// `iface` a SocketCAN interface (or "virtual:NAME" in process). Throws
// DeviceError with one line when the interface is missing or down, or this
// kernel has no CAN.
void scan_canopen(const std::string& iface, std::chrono::milliseconds listen,
                  const ScanLimits& limits, ScanResult& out);

}  // namespace animrt::commission
