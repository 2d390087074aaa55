#pragma once
// Pololu Maestro serial commands, both directions: the host encodes commands
// and decodes the two-byte answers; the simulated board parses the same
// command stream byte by byte.
//
// Compact protocol: COMMAND (MSB set), DATA... (MSB clear).
// Pololu protocol:  0xAA, DEVICE, COMMAND & 0x7F, DATA...  (daisy-chained boards)
// Targets, speeds and accelerations travel as two 7-bit data bytes (low
// first); answers (Get Position, Get Errors) are two plain bytes, low first.
// Targets are pulse widths in quarter-microseconds; 0 switches the channel off.

#include <cstddef>
#include <cstdint>
#include <span>

namespace animrt::maestro {

namespace cmd {
inline constexpr std::uint8_t set_target = 0x84;
inline constexpr std::uint8_t set_speed = 0x87;
inline constexpr std::uint8_t set_acceleration = 0x89;
inline constexpr std::uint8_t get_position = 0x90;
inline constexpr std::uint8_t get_moving_state = 0x93;
inline constexpr std::uint8_t set_multiple_targets = 0x9F;
inline constexpr std::uint8_t get_errors = 0xA1;
inline constexpr std::uint8_t go_home = 0xA2;
inline constexpr std::uint8_t pololu = 0xAA;
inline constexpr std::uint8_t mini_ssc = 0xFF;
}  // namespace cmd

// Error register bits (Get Errors).
namespace error_bit {
inline constexpr std::uint16_t serial_signal = 1u << 0;
inline constexpr std::uint16_t serial_overrun = 1u << 1;
inline constexpr std::uint16_t serial_buffer_full = 1u << 2;
inline constexpr std::uint16_t serial_crc = 1u << 3;
inline constexpr std::uint16_t serial_protocol = 1u << 4;
inline constexpr std::uint16_t serial_timeout = 1u << 5;
inline constexpr std::uint16_t script_stack = 1u << 6;
inline constexpr std::uint16_t script_call_stack = 1u << 7;
inline constexpr std::uint16_t script_program_counter = 1u << 8;
}  // namespace error_bit

inline constexpr std::uint16_t kMaxValue = 0x3FFF;                // 14 bits in two data bytes
inline constexpr std::uint8_t kDefaultDevice = 12;                // factory device number
inline constexpr std::size_t kMaxChannels = 24;                   // Mini Maestro 24
inline constexpr std::size_t kMaxCommand = 4 + 2 * kMaxChannels;  // Pololu-form multi-target

enum class Form : std::uint8_t { compact, pololu };

// Which board a command is for: compact (every board on the line obeys) or
// the Pololu form with a device number 0..127.
struct Address {
  Form form = Form::compact;
  std::uint8_t device = kDefaultDevice;
};

// Encoders return the number of bytes written to `out`, or 0 when `out` is too
// small or an argument does not fit its data bytes (channel > 127, value >
// 0x3FFF, device > 127, no targets).
std::size_t encode_set_target(Address a, std::uint8_t channel, std::uint16_t target,
                              std::span<std::uint8_t> out);
std::size_t encode_set_multiple_targets(Address a, std::uint8_t first_channel,
                                        std::span<const std::uint16_t> targets,
                                        std::span<std::uint8_t> out);
std::size_t encode_set_speed(Address a, std::uint8_t channel, std::uint16_t speed,
                             std::span<std::uint8_t> out);
std::size_t encode_set_acceleration(Address a, std::uint8_t channel, std::uint16_t acceleration,
                                    std::span<std::uint8_t> out);
std::size_t encode_get_position(Address a, std::uint8_t channel, std::span<std::uint8_t> out);
std::size_t encode_get_errors(Address a, std::span<std::uint8_t> out);

// A two-byte answer, low byte first.
inline std::uint16_t decode_answer(const std::uint8_t* two) {
  return static_cast<std::uint16_t>(two[0] | (two[1] << 8));
}
inline void encode_answer(std::uint16_t value, std::uint8_t* two) {
  two[0] = static_cast<std::uint8_t>(value & 0xFF);
  two[1] = static_cast<std::uint8_t>(value >> 8);
}

// One decoded command (device side).
struct Command {
  std::uint8_t command = 0;  // compact command byte (MSB set)
  bool pololu_form = false;
  std::uint8_t device = 0;   // Pololu form only
  std::uint8_t channel = 0;  // first channel, where the command has one
  std::uint16_t value = 0;   // target / speed / acceleration
  std::uint8_t count = 0;    // Set Multiple Targets
  std::uint16_t targets[kMaxChannels] = {};
};

enum class ParseResult : std::uint8_t {
  need_more,       // byte consumed, command not complete
  command,         // a command is complete (see Parser::command())
  protocol_error,  // stray data byte, unknown command, or a command cut short
                   // by a new command byte (that byte starts the new command)
};

// Byte-wise parser of a command stream, as a board reads its RX line.
// Mini SSC (0xFF) commands are consumed and ignored.
class Parser {
 public:
  ParseResult feed(std::uint8_t byte);
  const Command& command() const { return command_; }
  void reset();

 private:
  ParseResult begin(std::uint8_t command_byte, bool pololu_form);
  ParseResult finish_data();

  enum class State : std::uint8_t { idle, pololu_device, pololu_command, data, mini_ssc };
  State state_ = State::idle;
  Command command_;
  std::uint8_t data_[2 + 2 * kMaxChannels] = {};
  std::size_t have_ = 0;
  std::size_t need_ = 0;  // data bytes of the command; for multi-target known after the count
  int mini_ssc_left_ = 0;
};

// Data bytes a compact command byte takes, or -1 for an unknown command
// (Set Multiple Targets: -2, its length follows from its first data byte).
int data_length(std::uint8_t command_byte);

}  // namespace animrt::maestro
