#include "animrt/bridge/maestro/maestro_codec.hpp"

namespace animrt::maestro {
namespace {

// Writes the command byte (compact) or 0xAA, device, command & 0x7F (Pololu).
// Returns the header length, 0 if it does not fit.
std::size_t header(Address a, std::uint8_t command, std::size_t data, std::span<std::uint8_t> out) {
  const std::size_t head = a.form == Form::compact ? 1 : 3;
  if (out.size() < head + data || a.device > 0x7F) return 0;
  if (a.form == Form::compact) {
    out[0] = command;
  } else {
    out[0] = cmd::pololu;
    out[1] = a.device;
    out[2] = static_cast<std::uint8_t>(command & 0x7F);
  }
  return head;
}

void put14(std::uint16_t value, std::uint8_t* p) {
  p[0] = static_cast<std::uint8_t>(value & 0x7F);
  p[1] = static_cast<std::uint8_t>((value >> 7) & 0x7F);
}

std::uint16_t get14(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 7));
}

std::size_t channel_value(Address a, std::uint8_t command, std::uint8_t channel,
                          std::uint16_t value, std::span<std::uint8_t> out) {
  if (channel > 0x7F || value > kMaxValue) return 0;
  const std::size_t h = header(a, command, 3, out);
  if (h == 0) return 0;
  out[h] = channel;
  put14(value, &out[h + 1]);
  return h + 3;
}

}  // namespace

int data_length(std::uint8_t command_byte) {
  switch (command_byte) {
    case cmd::set_target:
    case cmd::set_speed:
    case cmd::set_acceleration:
      return 3;
    case cmd::get_position:
      return 1;
    case cmd::get_moving_state:
    case cmd::get_errors:
    case cmd::go_home:
      return 0;
    case cmd::set_multiple_targets:
      return -2;
    default:
      return -1;
  }
}

std::size_t encode_set_target(Address a, std::uint8_t channel, std::uint16_t target,
                              std::span<std::uint8_t> out) {
  return channel_value(a, cmd::set_target, channel, target, out);
}

std::size_t encode_set_speed(Address a, std::uint8_t channel, std::uint16_t speed,
                             std::span<std::uint8_t> out) {
  return channel_value(a, cmd::set_speed, channel, speed, out);
}

std::size_t encode_set_acceleration(Address a, std::uint8_t channel, std::uint16_t acceleration,
                                    std::span<std::uint8_t> out) {
  return channel_value(a, cmd::set_acceleration, channel, acceleration, out);
}

std::size_t encode_set_multiple_targets(Address a, std::uint8_t first_channel,
                                        std::span<const std::uint16_t> targets,
                                        std::span<std::uint8_t> out) {
  if (targets.empty() || targets.size() > 0x7F || first_channel > 0x7F) return 0;
  const std::size_t data = 2 + 2 * targets.size();
  const std::size_t h = header(a, cmd::set_multiple_targets, data, out);
  if (h == 0) return 0;
  out[h] = static_cast<std::uint8_t>(targets.size());
  out[h + 1] = first_channel;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    if (targets[i] > kMaxValue) return 0;
    put14(targets[i], &out[h + 2 + 2 * i]);
  }
  return h + data;
}

std::size_t encode_get_position(Address a, std::uint8_t channel, std::span<std::uint8_t> out) {
  if (channel > 0x7F) return 0;
  const std::size_t h = header(a, cmd::get_position, 1, out);
  if (h == 0) return 0;
  out[h] = channel;
  return h + 1;
}

std::size_t encode_get_errors(Address a, std::span<std::uint8_t> out) {
  return header(a, cmd::get_errors, 0, out);
}

// ---- device side ----------------------------------------------------------

void Parser::reset() {
  state_ = State::idle;
  have_ = need_ = 0;
  mini_ssc_left_ = 0;
}

ParseResult Parser::begin(std::uint8_t command_byte, bool pololu_form) {
  const int length = data_length(command_byte);
  if (length == -1) {
    reset();
    return ParseResult::protocol_error;
  }
  command_ = Command{};
  command_.command = command_byte;
  command_.pololu_form = pololu_form;
  command_.device = pololu_form ? data_[0] : 0;
  have_ = 0;
  need_ = length == -2 ? 1 : static_cast<std::size_t>(length);  // multi-target: the count first
  state_ = State::data;
  if (need_ == 0) return finish_data();
  return ParseResult::need_more;
}

ParseResult Parser::finish_data() {
  Command& c = command_;
  switch (c.command) {
    case cmd::set_target:
    case cmd::set_speed:
    case cmd::set_acceleration:
      c.channel = data_[0];
      c.value = get14(&data_[1]);
      break;
    case cmd::get_position:
      c.channel = data_[0];
      break;
    case cmd::set_multiple_targets:
      c.count = data_[0];
      c.channel = data_[1];
      for (std::size_t i = 0; i < c.count; ++i) c.targets[i] = get14(&data_[2 + 2 * i]);
      break;
    default:
      break;
  }
  state_ = State::idle;
  have_ = need_ = 0;
  return ParseResult::command;
}

ParseResult Parser::feed(std::uint8_t byte) {
  const bool command_byte = (byte & 0x80) != 0;
  if (state_ == State::mini_ssc) {  // Mini SSC data bytes may have any value
    if (--mini_ssc_left_ == 0) state_ = State::idle;
    return ParseResult::need_more;
  }
  if (command_byte) {
    // A command byte in the middle of a command cuts it short: an error, and
    // the new byte starts the next command.
    const bool interrupted = state_ != State::idle;
    ParseResult r;
    if (byte == cmd::pololu) {
      state_ = State::pololu_device;
      r = ParseResult::need_more;
    } else if (byte == cmd::mini_ssc) {
      state_ = State::mini_ssc;
      mini_ssc_left_ = 2;
      r = ParseResult::need_more;
    } else {
      state_ = State::idle;
      r = begin(byte, false);
    }
    if (interrupted) {
      // The new command is kept; report the error now. A zero-data command
      // completed by this very byte is lost, as its error report wins.
      if (r == ParseResult::command) reset();
      return ParseResult::protocol_error;
    }
    return r;
  }
  switch (state_) {
    case State::idle:
      return ParseResult::protocol_error;  // stray data byte
    case State::pololu_device:
      data_[0] = byte;  // kept for begin()
      state_ = State::pololu_command;
      return ParseResult::need_more;
    case State::pololu_command:
      return begin(static_cast<std::uint8_t>(byte | 0x80), true);
    case State::data:
      data_[have_++] = byte;
      if (command_.command == cmd::set_multiple_targets && have_ == 1) {
        if (byte == 0 || byte > kMaxChannels) {
          reset();
          return ParseResult::protocol_error;
        }
        need_ = 2 + 2 * static_cast<std::size_t>(byte);
      }
      if (have_ < need_) return ParseResult::need_more;
      return finish_data();
    case State::mini_ssc:
      break;
  }
  return ParseResult::need_more;
}

}  // namespace animrt::maestro
