#pragma once
// CANopen (CiA 301) frames the runtime and the simulated drive exchange:
// NMT, SYNC, heartbeat, EMCY, expedited SDO and PDO payloads. Both ends of
// the wire use these, like the Dynamixel codec. Pre-defined connection set:
// the COB-ID is a function code plus the node id (1..127).

#include <linux/can.h>

#include <cstdint>
#include <span>

namespace animrt::canopen {

inline constexpr canid_t kNmtId = 0x000;
inline constexpr canid_t kSyncId = 0x080;
inline constexpr canid_t kEmcyBase = 0x080;       // + node
inline constexpr canid_t kTpdo1Base = 0x180;      // + node, device -> master
inline constexpr canid_t kRpdo1Base = 0x200;      // + node, master -> device
inline constexpr canid_t kTpdo2Base = 0x280;      // + node, device -> master
inline constexpr canid_t kTsdoBase = 0x580;       // + node, SDO server -> client
inline constexpr canid_t kRsdoBase = 0x600;       // + node, SDO client -> server
inline constexpr canid_t kHeartbeatBase = 0x700;  // + node
inline constexpr int kMaxNodeId = 127;

enum class NmtCommand : std::uint8_t {
  start = 0x01,
  stop = 0x02,
  enter_pre_operational = 0x80,
  reset_node = 0x81,
  reset_communication = 0x82,
};

// NMT state as carried by the heartbeat (boot_up only in the boot-up message).
enum class NmtState : std::uint8_t {
  boot_up = 0x00,
  stopped = 0x04,
  operational = 0x05,
  pre_operational = 0x7F,
};
const char* to_string(NmtState state);

can_frame nmt(NmtCommand command, std::uint8_t node);  // node 0: every node
can_frame sync();                                      // no data (no counter)
can_frame heartbeat(std::uint8_t node, NmtState state);

// EMCY: error code (16 bits), error register (object 1001h), 5 vendor bytes.
struct Emcy {
  std::uint16_t code = 0;  // 0x0000: error reset / no error
  std::uint8_t error_register = 0;
  std::uint8_t vendor[5] = {};
};
can_frame emcy(std::uint8_t node, const Emcy& e);
bool parse_emcy(const can_frame& frame, Emcy& out);  // 8 data bytes expected
// The CiA 301 / 402 error code class, e.g. "current" for 0x2310.
const char* emcy_class(std::uint16_t code);

// Expedited SDO (1, 2 or 4 data bytes in one frame).
enum class SdoKind : std::uint8_t {
  download_request,   // client writes (ccs 1)
  download_response,  // server confirms (scs 3)
  upload_request,     // client reads (ccs 2)
  upload_response,    // server answers with the data (scs 2)
  abort,              // either side (cs 4)
  unsupported,        // segmented / block transfers, malformed
};
struct Sdo {
  SdoKind kind = SdoKind::unsupported;
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint32_t value = 0;  // data (little-endian) or abort code
  std::uint8_t size = 0;    // data bytes when indicated (1..4), else 0
  bool expedited = false;   // download request / upload response: data in the frame
};
can_frame sdo_download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                       std::uint32_t value, std::uint8_t size);
can_frame sdo_upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub);
can_frame sdo_download_response(std::uint8_t node, std::uint16_t index, std::uint8_t sub);
can_frame sdo_upload_response(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                              std::uint32_t value, std::uint8_t size);
// From the server (0x580 + node) or, with from_client, from the client (0x600 + node).
can_frame sdo_abort(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t code,
                    bool from_client = false);
// Decodes the 8 data bytes of an SDO frame (either direction).
Sdo parse_sdo(const can_frame& frame);
// CiA 301 abort code text, e.g. "object does not exist in the object dictionary".
const char* sdo_abort_text(std::uint32_t code);

namespace abort_code {
inline constexpr std::uint32_t toggle_bit = 0x05030000;
inline constexpr std::uint32_t timeout = 0x05040000;
inline constexpr std::uint32_t command_specifier = 0x05040001;
inline constexpr std::uint32_t unsupported_access = 0x06010000;
inline constexpr std::uint32_t write_only = 0x06010001;
inline constexpr std::uint32_t read_only = 0x06010002;
inline constexpr std::uint32_t no_object = 0x06020000;
inline constexpr std::uint32_t not_mappable = 0x06040041;
inline constexpr std::uint32_t pdo_length = 0x06040042;
inline constexpr std::uint32_t parameter_incompatible = 0x06040043;
inline constexpr std::uint32_t length_mismatch = 0x06070010;
inline constexpr std::uint32_t no_subindex = 0x06090011;
inline constexpr std::uint32_t value_range = 0x06090030;
inline constexpr std::uint32_t value_too_high = 0x06090031;
inline constexpr std::uint32_t value_too_low = 0x06090032;
inline constexpr std::uint32_t general = 0x08000000;
inline constexpr std::uint32_t device_state = 0x08000022;
}  // namespace abort_code

// Little-endian field access inside a PDO payload.
inline void put_le(std::uint8_t* p, std::uint32_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline std::uint32_t get_le(const std::uint8_t* p, int bytes) {
  std::uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}

// A PDO mapping entry (objects 1600h.., 1A00h..): index 16 | sub 8 | bits 8.
inline constexpr std::uint32_t mapping(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) {
  return (static_cast<std::uint32_t>(index) << 16) | (static_cast<std::uint32_t>(sub) << 8) | bits;
}

}  // namespace animrt::canopen
