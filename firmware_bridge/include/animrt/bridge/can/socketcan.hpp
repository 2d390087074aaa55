#pragma once
// SocketCAN: a raw CAN socket (AF_CAN, CAN_RAW) bound to one interface,
// non-blocking, with error frames enabled. Works for real controllers (can0)
// and for the kernel's virtual CAN (vcan0) alike.

#include <memory>
#include <string>

#include "animrt/bridge/can/can_transport.hpp"

namespace animrt {

// Whether this kernel can create a CAN socket at all ("" if so, otherwise why
// not, e.g. "this kernel has no CAN support (AF_CAN: Address family not
// supported by protocol); load the can and can-raw modules").
std::string socketcan_unavailable_reason();

// Opens `interface`. Throws DeviceError naming the interface when AF_CAN is
// missing, the interface does not exist, or it is down.
std::unique_ptr<CanFrameTransport> open_socketcan(const std::string& interface);

}  // namespace animrt
