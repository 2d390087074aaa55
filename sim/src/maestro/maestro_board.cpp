#include "animrt/sim/maestro/maestro_board.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace animrt::sim {

MaestroBoard::MaestroBoard(int device_number, int channels,
                           std::span<const MaestroChannelSetup> setup, Nanos now)
    : device_(device_number),
      channels_(static_cast<std::size_t>(channels)),
      tick_time_(now),
      last_command_(now) {
  for (const MaestroChannelSetup& s : setup) {
    if (s.channel < 0 || s.channel >= channels) throw std::out_of_range("Maestro channel");
    Channel& c = channels_[static_cast<std::size_t>(s.channel)];
    c.min_q = static_cast<std::uint16_t>(std::ceil(s.min_us * 4.0));
    c.max_q = static_cast<std::uint16_t>(std::floor(s.max_us * 4.0));
  }
}

void MaestroBoard::set_target(Channel& c, std::uint16_t target) const {
  if (target == 0) {  // pulses off
    c.target = c.position = 0;
    c.step = 0.0;
    return;
  }
  c.target = std::clamp(target, c.min_q, c.max_q);
  if (c.position == 0 || (c.speed == 0 && c.acceleration == 0)) {
    c.position = c.target;
    c.step = 0.0;
  }
}

void MaestroBoard::tick(Channel& c) const {
  if (c.position == 0 || c.position == c.target) {
    c.step = 0.0;
    return;
  }
  const double remaining = std::abs(static_cast<double>(c.target) - c.position);
  double step = remaining;  // no limits: jump
  if (c.acceleration > 0) {
    const double a = c.acceleration / 8.0;  // per tick
    // Speed up by a, but never so fast that a cannot stop at the target.
    step = std::min(c.step + a, std::sqrt(2.0 * a * remaining));
    step = std::max(step, std::min(a, remaining));
  }
  if (c.speed > 0) step = std::min(step, static_cast<double>(c.speed));
  step = std::min(step, remaining);
  const double dir = c.target > c.position ? 1.0 : -1.0;
  const double next = c.position + dir * step;
  c.position = static_cast<std::uint16_t>(std::lround(next));
  if (std::abs(static_cast<double>(c.target) - c.position) < 0.5) c.position = c.target;
  c.step = step;
}

void MaestroBoard::advance_ticks(Nanos now) {
  while (now - tick_time_ >= kTick) {
    tick_time_ += kTick;
    for (Channel& c : channels_) tick(c);
  }
}

void MaestroBoard::advance(Nanos now) {
  while (serial_timeout_ > 0 && now - last_command_ > serial_timeout_) {
    const Nanos fire = last_command_ + serial_timeout_;
    advance_ticks(fire);
    fail(maestro::error_bit::serial_timeout);
    last_command_ = fire;
  }
  advance_ticks(now);
}

void MaestroBoard::fail(std::uint16_t bits) {
  errors_ |= bits;
  for (Channel& c : channels_) set_target(c, 0);  // home = off
}

void MaestroBoard::protocol_error(Nanos now) {
  advance(now);
  fail(maestro::error_bit::serial_protocol);
}

void MaestroBoard::raise_errors(std::uint16_t bits, Nanos now) {
  advance(now);
  fail(bits);
}

void MaestroBoard::handle(const maestro::Command& command, Nanos now,
                          std::vector<std::uint8_t>& out) {
  advance(now);
  const auto channel_ok = [&](int ch) { return ch >= 0 && ch < channels(); };
  // Every valid command restarts the serial timeout (an invalid one fails
  // below, before this counts).
  bool valid = false;
  switch (command.command) {
    case maestro::cmd::go_home:
    case maestro::cmd::get_errors:
    case maestro::cmd::get_moving_state:
      valid = true;
      break;
    case maestro::cmd::set_target:
    case maestro::cmd::set_speed:
    case maestro::cmd::set_acceleration:
    case maestro::cmd::get_position:
      valid = channel_ok(command.channel);
      break;
    case maestro::cmd::set_multiple_targets:
      valid = channel_ok(command.channel) && channel_ok(command.channel + command.count - 1);
      break;
    default:
      break;
  }
  if (valid) last_command_ = std::max(last_command_, now);
  std::uint8_t answer[2];
  switch (command.command) {
    case maestro::cmd::set_target:
    case maestro::cmd::set_speed:
    case maestro::cmd::set_acceleration: {
      if (!channel_ok(command.channel)) return fail(maestro::error_bit::serial_protocol);
      Channel& c = channels_[command.channel];
      if (command.command == maestro::cmd::set_target) {
        set_target(c, command.value);
      } else if (command.command == maestro::cmd::set_speed) {
        c.speed = command.value;
      } else {
        c.acceleration = std::min<std::uint16_t>(command.value, 255);
      }
      return;
    }
    case maestro::cmd::set_multiple_targets: {
      if (!channel_ok(command.channel) || !channel_ok(command.channel + command.count - 1)) {
        return fail(maestro::error_bit::serial_protocol);
      }
      for (int i = 0; i < command.count; ++i) {
        set_target(channels_[command.channel + i], command.targets[i]);
      }
      return;
    }
    case maestro::cmd::get_position: {
      if (!channel_ok(command.channel)) return fail(maestro::error_bit::serial_protocol);
      maestro::encode_answer(channels_[command.channel].position, answer);
      out.insert(out.end(), answer, answer + 2);
      return;
    }
    case maestro::cmd::get_moving_state: {
      bool moving = false;
      for (const Channel& c : channels_) moving = moving || c.position != c.target;
      out.push_back(moving ? 1 : 0);
      return;
    }
    case maestro::cmd::get_errors:
      maestro::encode_answer(errors_, answer);
      out.insert(out.end(), answer, answer + 2);
      errors_ = 0;
      return;
    case maestro::cmd::go_home:
      for (Channel& c : channels_) set_target(c, 0);
      return;
    default:
      return fail(maestro::error_bit::serial_protocol);
  }
}

}  // namespace animrt::sim
