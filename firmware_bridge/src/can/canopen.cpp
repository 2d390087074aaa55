#include "animrt/bridge/can/canopen.hpp"

namespace animrt::canopen {
namespace {

// SDO command specifier (bits 7-5 of byte 0) and the expedited flags.
constexpr std::uint8_t kCsMask = 0xE0;
constexpr std::uint8_t kExpedited = 0x02;
constexpr std::uint8_t kSizeIndicated = 0x01;

can_frame frame(canid_t id, std::uint8_t len) {
  can_frame f{};
  f.can_id = id;
  f.len = len;
  return f;
}

void put_multiplexer(can_frame& f, std::uint16_t index, std::uint8_t sub) {
  f.data[1] = static_cast<std::uint8_t>(index);
  f.data[2] = static_cast<std::uint8_t>(index >> 8);
  f.data[3] = sub;
}

std::uint8_t expedited_cs(std::uint8_t base, std::uint8_t size) {
  // n = number of bytes in 4..7 that hold no data.
  return static_cast<std::uint8_t>(base | ((4 - size) << 2) | kExpedited | kSizeIndicated);
}

}  // namespace

const char* to_string(NmtState state) {
  switch (state) {
    case NmtState::boot_up:
      return "boot-up";
    case NmtState::stopped:
      return "stopped";
    case NmtState::operational:
      return "operational";
    case NmtState::pre_operational:
      return "pre-operational";
  }
  return "unknown";
}

can_frame nmt(NmtCommand command, std::uint8_t node) {
  can_frame f = frame(kNmtId, 2);
  f.data[0] = static_cast<std::uint8_t>(command);
  f.data[1] = node;
  return f;
}

can_frame sync() { return frame(kSyncId, 0); }

can_frame heartbeat(std::uint8_t node, NmtState state) {
  can_frame f = frame(kHeartbeatBase + node, 1);
  f.data[0] = static_cast<std::uint8_t>(state);
  return f;
}

can_frame emcy(std::uint8_t node, const Emcy& e) {
  can_frame f = frame(kEmcyBase + node, 8);
  f.data[0] = static_cast<std::uint8_t>(e.code);
  f.data[1] = static_cast<std::uint8_t>(e.code >> 8);
  f.data[2] = e.error_register;
  for (int i = 0; i < 5; ++i) f.data[3 + i] = e.vendor[i];
  return f;
}

bool parse_emcy(const can_frame& f, Emcy& out) {
  if (f.len != 8) return false;
  out.code = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
  out.error_register = f.data[2];
  for (int i = 0; i < 5; ++i) out.vendor[i] = f.data[3 + i];
  return true;
}

const char* emcy_class(std::uint16_t code) {
  if (code == 0x0000) return "error reset";
  if ((code >> 8) == 0xFF) return "device specific";
  switch (code >> 12) {
    case 0x1:
      return "generic error";
    case 0x2:
      return "current";
    case 0x3:
      return "voltage";
    case 0x4:
      return "temperature";
    case 0x5:
      return "device hardware";
    case 0x6:
      return "device software";
    case 0x7:
      return "additional modules";
    case 0x8:
      if ((code & 0xFF00) == 0x8100) return "communication";
      if ((code & 0xFF00) == 0x8600) return "positioning controller";
      return "monitoring";
    case 0x9:
      return "external error";
    case 0xF:
      return "additional functions";
    default:
      return "unknown error class";
  }
}

can_frame sdo_download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                       std::uint32_t value, std::uint8_t size) {
  can_frame f = frame(kRsdoBase + node, 8);
  f.data[0] = expedited_cs(0x20, size);
  put_multiplexer(f, index, sub);
  put_le(f.data + 4, value, size);
  return f;
}

can_frame sdo_upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  can_frame f = frame(kRsdoBase + node, 8);
  f.data[0] = 0x40;
  put_multiplexer(f, index, sub);
  return f;
}

can_frame sdo_download_response(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  can_frame f = frame(kTsdoBase + node, 8);
  f.data[0] = 0x60;
  put_multiplexer(f, index, sub);
  return f;
}

can_frame sdo_upload_response(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                              std::uint32_t value, std::uint8_t size) {
  can_frame f = frame(kTsdoBase + node, 8);
  f.data[0] = expedited_cs(0x40, size);
  put_multiplexer(f, index, sub);
  put_le(f.data + 4, value, size);
  return f;
}

can_frame sdo_abort(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t code,
                    bool from_client) {
  can_frame f = frame((from_client ? kRsdoBase : kTsdoBase) + node, 8);
  f.data[0] = 0x80;
  put_multiplexer(f, index, sub);
  put_le(f.data + 4, code, 4);
  return f;
}

Sdo parse_sdo(const can_frame& f) {
  Sdo s;
  if (f.len != 8) return s;
  const std::uint8_t cs = f.data[0];
  s.index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
  s.subindex = f.data[3];
  const bool from_server = (f.can_id & 0x780) == kTsdoBase;
  const bool expedited = (cs & kExpedited) != 0;
  const bool sized = (cs & kSizeIndicated) != 0;
  const auto data_size = [&]() -> std::uint8_t {
    if (!expedited) return 0;
    return sized ? static_cast<std::uint8_t>(4 - ((cs >> 2) & 0x3)) : 4;
  };
  switch (cs & kCsMask) {
    case 0x20:  // ccs 1: initiate download
      if (from_server) return s;
      s.kind = SdoKind::download_request;
      s.expedited = expedited;
      s.size = data_size();
      s.value = expedited ? get_le(f.data + 4, s.size) : 0;
      return s;
    case 0x40:  // ccs 2 (upload request) / scs 2 (upload response)
      if (from_server) {
        s.kind = SdoKind::upload_response;
        s.expedited = expedited;
        s.size = data_size();
        s.value = expedited ? get_le(f.data + 4, s.size) : 0;
      } else {
        s.kind = SdoKind::upload_request;
      }
      return s;
    case 0x60:  // scs 3: initiate download response
      if (from_server) s.kind = SdoKind::download_response;
      return s;
    case 0x80:
      s.kind = SdoKind::abort;
      s.value = get_le(f.data + 4, 4);
      return s;
    default:
      return s;
  }
}

const char* sdo_abort_text(std::uint32_t code) {
  switch (code) {
    case abort_code::toggle_bit:
      return "toggle bit not alternated";
    case abort_code::timeout:
      return "SDO protocol timed out";
    case abort_code::command_specifier:
      return "client/server command specifier not valid or unknown";
    case abort_code::unsupported_access:
      return "unsupported access to an object";
    case abort_code::write_only:
      return "attempt to read a write only object";
    case abort_code::read_only:
      return "attempt to write a read only object";
    case abort_code::no_object:
      return "object does not exist in the object dictionary";
    case abort_code::not_mappable:
      return "object cannot be mapped to the PDO";
    case abort_code::pdo_length:
      return "the mapped objects would exceed the PDO length";
    case abort_code::parameter_incompatible:
      return "general parameter incompatibility";
    case 0x06060000:
      return "access failed due to a hardware error";
    case abort_code::length_mismatch:
      return "data type does not match, length of service parameter does not match";
    case 0x06070012:
      return "data type does not match, length of service parameter too high";
    case 0x06070013:
      return "data type does not match, length of service parameter too low";
    case abort_code::no_subindex:
      return "sub-index does not exist";
    case abort_code::value_range:
      return "invalid value for parameter (download only)";
    case abort_code::value_too_high:
      return "value of parameter written too high";
    case abort_code::value_too_low:
      return "value of parameter written too low";
    case abort_code::general:
      return "general error";
    case 0x08000020:
      return "data cannot be transferred or stored to the application";
    case 0x08000021:
      return "data cannot be transferred or stored because of local control";
    case abort_code::device_state:
      return "data cannot be transferred or stored because of the present device state";
    default:
      return "unknown abort code";
  }
}

}  // namespace animrt::canopen
