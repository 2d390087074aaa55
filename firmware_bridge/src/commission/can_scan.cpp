#include "animrt/bridge/commission/can_scan.hpp"

#include <cstdio>
#include <map>
#include <optional>

#include "animrt/bridge/can/can_transport.hpp"
#include "animrt/bridge/can/canopen.hpp"

namespace animrt::commission {
namespace {

using Clock = std::chrono::steady_clock;

std::string hex32(std::uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08X", v);
  return text;
}

const char* nmt_state(std::uint8_t state) {
  switch (state & 0x7F) {
    case 0x00:
      return "boot-up";
    case 0x04:
      return "stopped";
    case 0x05:
      return "operational";
    case 0x7F:
      return "pre-operational";
    default:
      return "unknown state";
  }
}

// One expedited SDO upload; the value, or nothing on silence or an abort.
std::optional<std::uint32_t> upload(CanFrameTransport& can, std::uint8_t node, std::uint16_t index,
                                    std::uint8_t sub, std::chrono::microseconds timeout,
                                    bool& answered) {
  if (!can.send(canopen::sdo_upload(node, index, sub))) return std::nullopt;
  const auto end = Clock::now() + timeout;
  can_frame frame{};
  while (Clock::now() < end) {
    const auto left = std::chrono::ceil<std::chrono::microseconds>(end - Clock::now());
    if (!can.receive(frame, left)) break;
    if ((frame.can_id & CAN_SFF_MASK) != canopen::kTsdoBase + node) continue;
    const canopen::Sdo sdo = canopen::parse_sdo(frame);
    if (sdo.index != index || sdo.subindex != sub) continue;
    answered = true;
    if (sdo.kind == canopen::SdoKind::upload_response && sdo.expedited) return sdo.value;
    return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace

void scan_canopen(const std::string& iface, std::chrono::milliseconds listen,
                  const ScanLimits& limits, ScanResult& out) {
  std::unique_ptr<CanFrameTransport> can = open_can(iface);
  std::map<int, std::uint8_t> heartbeat;  // node -> NMT state
  const auto end = Clock::now() + listen;
  can_frame frame{};
  while (Clock::now() < end) {
    const auto left = std::chrono::ceil<std::chrono::microseconds>(end - Clock::now());
    if (!can->receive(frame, left)) break;
    const canid_t id = frame.can_id & CAN_SFF_MASK;
    if ((frame.can_id & CAN_EFF_FLAG) == 0 && id > canopen::kHeartbeatBase &&
        id <= canopen::kHeartbeatBase + canopen::kMaxNodeId && frame.can_dlc >= 1) {
      heartbeat[static_cast<int>(id - canopen::kHeartbeatBase)] = frame.data[0];
    }
  }
  if (limits.progress) {
    limits.progress("canopen on " + iface + ": " + std::to_string(heartbeat.size()) +
                    " node(s) sent heartbeats");
  }
  const int first = std::max(limits.first_id, 1);
  const int last = std::min(limits.last_id, canopen::kMaxNodeId);
  for (int node = first; node <= last; ++node) {
    bool answered = false;
    const auto n = static_cast<std::uint8_t>(node);
    const auto type = upload(*can, n, 0x1000, 0, limits.answer_timeout, answered);
    const auto it = heartbeat.find(node);
    if (!answered && it == heartbeat.end()) continue;
    FoundDevice d;
    d.protocol = "canopen";
    d.id = node;
    if (type) d.model = "device type " + hex32(*type);
    const auto vendor = upload(*can, n, 0x1018, 1, limits.answer_timeout, answered);
    const auto product = upload(*can, n, 0x1018, 2, limits.answer_timeout, answered);
    const auto revision = upload(*can, n, 0x1018, 3, limits.answer_timeout, answered);
    if (vendor || product) {
      d.model += (d.model.empty() ? "" : ", ") + std::string("vendor ") +
                 (vendor ? hex32(*vendor) : "?") + " product " + (product ? hex32(*product) : "?");
    }
    if (revision) d.firmware = hex32(*revision);
    d.note = it != heartbeat.end() ? std::string("heartbeat: ") + nmt_state(it->second)
                                   : "no heartbeat heard";
    if (!answered) d.note += "; no SDO answer";
    out.devices.push_back(std::move(d));
  }
  if (can->errors().error_frames > 0) {
    out.garbled.push_back("canopen on " + iface + ": " + describe_errors(can->errors()));
  }
}

}  // namespace animrt::commission
