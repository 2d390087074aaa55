#pragma once
// CiA 402 drive profile: the controlword / statusword state machine (both
// the drive's side, which the simulated drive runs, and the master's, which
// picks the controlword that leads to a goal state) and the objects a
// position-mode drive is driven through.

#include <cstdint>

namespace animrt::cia402 {

namespace obj {
inline constexpr std::uint16_t device_type = 0x1000;         // u32, 0x0192 in the low word
inline constexpr std::uint16_t error_register = 0x1001;      // u8
inline constexpr std::uint16_t heartbeat_consumer = 0x1016;  // :01 u32, node << 16 | ms
inline constexpr std::uint16_t heartbeat_time = 0x1017;      // u16, ms
inline constexpr std::uint16_t identity = 0x1018;            // record
inline constexpr std::uint16_t rpdo1_comm = 0x1400;          // :1 COB-ID, :2 transmission type
inline constexpr std::uint16_t rpdo1_map = 0x1600;
inline constexpr std::uint16_t tpdo1_comm = 0x1800;
inline constexpr std::uint16_t tpdo1_map = 0x1A00;
inline constexpr std::uint16_t tpdo2_comm = 0x1801;
inline constexpr std::uint16_t tpdo2_map = 0x1A01;
inline constexpr std::uint16_t abort_connection_option = 0x6007;     // i16
inline constexpr std::uint16_t error_code = 0x603F;                  // u16, last EMCY code
inline constexpr std::uint16_t controlword = 0x6040;                 // u16
inline constexpr std::uint16_t statusword = 0x6041;                  // u16
inline constexpr std::uint16_t quick_stop_option = 0x605A;           // i16
inline constexpr std::uint16_t modes_of_operation = 0x6060;          // i8
inline constexpr std::uint16_t modes_of_operation_display = 0x6061;  // i8
inline constexpr std::uint16_t position_actual = 0x6064;             // i32
inline constexpr std::uint16_t velocity_actual = 0x606C;             // i32
inline constexpr std::uint16_t motor_rated_current = 0x6075;         // u32, mA
inline constexpr std::uint16_t current_actual = 0x6078;   // i16, per mille of rated current
inline constexpr std::uint16_t dc_link_voltage = 0x6079;  // u32, mV
inline constexpr std::uint16_t target_position = 0x607A;  // i32
inline constexpr std::uint16_t home_offset = 0x607C;      // i32: the position the home reads
inline constexpr std::uint16_t homing_method = 0x6098;    // i8
inline constexpr std::uint16_t homing_speeds = 0x6099;    // u32 :01 switch, :02 zero
inline constexpr std::uint16_t homing_accel = 0x609A;     // u32
}  // namespace obj

inline constexpr std::uint32_t kDeviceProfile = 402;      // low word of 1000h
inline constexpr std::int8_t kModeCsp = 8;                // cyclic synchronous position
inline constexpr std::uint32_t kPdoInvalid = 0x80000000;  // COB-ID bit 31

inline constexpr std::int8_t kModeHoming = 6;
// Homing on the current position: 37 in today's profile, 35 in older ones.
inline constexpr std::int8_t kHomingHere = 37;
inline constexpr std::int8_t kHomingHereOld = 35;
// Homing mode: controlword bit 4 starts it (rising edge); statusword bits
// 10 (target reached), 12 (homing attained), 13 (homing error).
inline constexpr std::uint16_t kCwHomingStart = 0x0010;
inline constexpr std::uint16_t kSwTargetReached = 0x0400;
inline constexpr std::uint16_t kSwHomingAttained = 0x1000;
inline constexpr std::uint16_t kSwHomingError = 0x2000;

enum class State : std::uint8_t {
  not_ready_to_switch_on,
  switch_on_disabled,
  ready_to_switch_on,
  switched_on,
  operation_enabled,
  quick_stop_active,
  fault_reaction_active,
  fault,
};
const char* to_string(State state);

// Statusword bits 0-3, 5, 6 for a state (the drive side also sets bit 4,
// voltage enabled, and bit 9, remote).
std::uint16_t state_bits(State state);
State decode_statusword(std::uint16_t statusword);

namespace cw {
inline constexpr std::uint16_t disable_voltage = 0x0000;
inline constexpr std::uint16_t quick_stop = 0x0002;
inline constexpr std::uint16_t shutdown = 0x0006;
inline constexpr std::uint16_t switch_on = 0x0007;  // also "disable operation"
inline constexpr std::uint16_t enable_operation = 0x000F;
inline constexpr std::uint16_t fault_reset = 0x0080;  // acts on the rising edge of bit 7
}  // namespace cw

enum class Command : std::uint8_t {
  none,
  shutdown,
  switch_on,
  enable_operation,  // "switch on + enable operation" from ready, "enable" from switched on
  disable_voltage,
  quick_stop,
  fault_reset,
};
const char* to_string(Command command);
// The command a controlword carries (fault reset only on the rising edge).
Command decode_controlword(std::uint16_t controlword, std::uint16_t previous);

// Drive side: the state after receiving `command` in `state` (transitions
// 2-12, 15, 16 of the profile; the automatic ones 0, 1, 13, 14 are the
// drive's own business). `transition` gets the profile's number, 0 if none.
State next_state(State state, Command command, int* transition = nullptr);

// Master side: the controlword that moves a drive in `state` one step toward
// `goal` (operation_enabled or switch_on_disabled). `previous` is the last
// controlword sent (a fault reset needs bit 7 low first).
std::uint16_t controlword_toward(State state, State goal, std::uint16_t previous);

}  // namespace animrt::cia402
