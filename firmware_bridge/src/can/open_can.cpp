// Which transport a CAN port names, and the error frame bookkeeping both
// transports share.

#include <linux/can/error.h>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/can/can_transport.hpp"
#include "animrt/bridge/can/socketcan.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"

namespace animrt {

std::unique_ptr<CanFrameTransport> open_can(const std::string& port) {
  if (port.starts_with(kVirtualCanPrefix)) {
    return VirtualCanBus::named(port.substr(kVirtualCanPrefix.size()))->attach();
  }
  return open_socketcan(port);
}

std::unique_ptr<CanFrameTransport> open_bus_can(const BusConfig& bus) {
  try {
    return open_can(bus.port);
  } catch (const DeviceError& e) {
    throw DeviceError("bus " + bus.name + ": " + e.what());
  }
}

int count_error_frame(const can_frame& frame, CanErrorCounters& c) {
  ++c.error_frames;
  const canid_t id = frame.can_id;
  if (id & CAN_ERR_LOSTARB) ++c.arbitration_lost;
  if (id & CAN_ERR_PROT) ++c.protocol_violations;
  if (id & CAN_ERR_ACK) ++c.no_ack;
  if (id & CAN_ERR_CRTL) {
    const std::uint8_t ctrl = frame.len > 1 ? frame.data[1] : 0;
    if (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) ++c.error_passive;
    if (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) ++c.error_warning;
    if (ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) ++c.rx_overflows;
  }
  if (id & CAN_ERR_BUSOFF) {
    ++c.bus_off;
    return 1;
  }
  if (id & CAN_ERR_RESTARTED) {
    ++c.restarts;
    return -1;
  }
  return 0;
}

std::string describe_errors(const CanErrorCounters& c) {
  std::string parts;
  auto add = [&](std::uint64_t n, const char* what) {
    if (n == 0) return;
    parts += (parts.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  add(c.bus_off, "bus-off");
  add(c.restarts, "restarted");
  add(c.error_passive, "error passive");
  add(c.error_warning, "error warning");
  add(c.arbitration_lost, "arbitration lost");
  add(c.protocol_violations, "protocol violation");
  add(c.no_ack, "no ack");
  add(c.rx_overflows, "receive overflow");
  std::string out;
  if (c.error_frames > 0) out = std::to_string(c.error_frames) + " error frames";
  if (!parts.empty()) out += (out.empty() ? "" : " ") + ("(" + parts + ")");
  if (c.tx_dropped > 0) {
    out += (out.empty() ? "" : ", ") + std::to_string(c.tx_dropped) + " frames not sent";
  }
  return out;
}

}  // namespace animrt
