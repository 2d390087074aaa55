#include "animrt/bridge/maestro/maestro_bus.hpp"

#include <algorithm>
#include <any>
#include <cmath>
#include <cstdio>
#include <utility>

#include "animrt/core/error.hpp"

namespace animrt {
namespace {

using std::chrono::steady_clock;
constexpr int kTries = 3;  // lifecycle transactions only

std::string hex16(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", v);
  return buf;
}

std::string error_names(std::uint16_t bits) {
  static constexpr std::pair<std::uint16_t, const char*> kNames[] = {
      {maestro::error_bit::serial_signal, "serial signal"},
      {maestro::error_bit::serial_overrun, "serial overrun"},
      {maestro::error_bit::serial_buffer_full, "serial buffer full"},
      {maestro::error_bit::serial_crc, "serial CRC"},
      {maestro::error_bit::serial_protocol, "serial protocol"},
      {maestro::error_bit::serial_timeout, "serial timeout"},
      {maestro::error_bit::script_stack, "script stack"},
      {maestro::error_bit::script_call_stack, "script call stack"},
      {maestro::error_bit::script_program_counter, "script program counter"},
  };
  std::string out = hex16(bits);
  std::string names;
  for (const auto& [bit, name] : kNames) {
    if (bits & bit) names += (names.empty() ? "" : ", ") + std::string(name);
  }
  return names.empty() ? out : out + " (" + names + ")";
}

}  // namespace

MaestroBus::MaestroBus(BusConfig config, std::unique_ptr<ByteTransport> transport)
    : config_(std::move(config)),
      transport_(std::move(transport)),
      timeout_(std::chrono::ceil<std::chrono::microseconds>(
          std::chrono::duration<double>(config_.timeout_s))) {
  const std::string bus = "bus " + config_.name + ": ";
  if (!transport_) throw DeviceError(bus + "no transport");
  transport_->set_timeout(timeout_);
  if (const auto* o = std::any_cast<MaestroBusOptions>(&config_.options)) options_ = *o;
  const std::size_t n = config_.actuators.size();
  channels_.resize(n);
  book_ = StatusBook(config_, transport_->port());
  present_.assign(n, 0);
  goal_.assign(n, 0);
  answered_.assign(n, 0);
  block_.reserve(maestro::kMaxChannels);
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    const auto* ch = std::any_cast<MaestroChannelOptions>(&b.options);
    if (ch == nullptr) throw DeviceError(bus + b.joint + " has no Maestro channel settings");
    if (ch->channel < 0 || ch->channel >= options_.channels) {
      throw DeviceError(bus + b.joint + ": channel " + std::to_string(ch->channel) +
                        " is not on a " + std::to_string(options_.channels) + "-channel board");
    }
    channels_[i] = *ch;
    if (options_.form == maestro::Form::compact) channels_[i].device = maestro::kDefaultDevice;
    auto board = std::find_if(boards_.begin(), boards_.end(), [&](const Board& bd) {
      return bd.address.device == channels_[i].device;
    });
    if (board == boards_.end()) {
      Board bd;
      bd.address = maestro::Address{options_.form, static_cast<std::uint8_t>(channels_[i].device)};
      boards_.push_back(bd);
      board = boards_.end() - 1;
    }
    for (std::size_t other : board->devices) {
      if (channels_[other].channel == ch->channel) {
        throw DeviceError(bus + "channel " + std::to_string(ch->channel) + " is used by " +
                          config_.actuators[other].joint + " and " + b.joint);
      }
    }
    board->devices.push_back(i);
  }
  for (Board& bd : boards_) {
    std::sort(bd.devices.begin(), bd.devices.end(), [&](std::size_t a, std::size_t c) {
      return channels_[a].channel < channels_[c].channel;
    });
  }
}

void MaestroBus::send(std::size_t length) {
  if (length > 0) transport_->write({tx_.data(), length});
}

std::size_t MaestroBus::receive(std::size_t want, std::chrono::microseconds timeout) {
  const auto deadline = steady_clock::now() + timeout;
  // A lockstep line (lockstep_line.hpp) says when nothing more will come.
  const bool line = transport_->follows_line();
  std::size_t got = 0;
  while (got < want) {
    const auto now = steady_clock::now();
    if (!line && now >= deadline) break;
    const std::size_t n = transport_->read(
        {rx_.data() + got, want - got},
        line ? timeout : std::chrono::ceil<std::chrono::microseconds>(deadline - now));
    if (n == 0 && (line || transport_->failure() != nullptr)) break;  // nothing will come
    got += n;
  }
  return got;
}

void MaestroBus::read_away_owed() {
  const bool line = transport_->follows_line();
  const auto left = std::chrono::ceil<std::chrono::microseconds>(owed_until_ - steady_clock::now());
  if (owed_bytes_ > 0 && (line || left.count() > 0)) {
    receive(std::min(owed_bytes_, rx_.size()), line ? timeout_ : left);
  }
  owed_bytes_ = 0;
}

bool MaestroBus::poll_board(Board& board, bool count) {
  std::size_t length = 0;
  std::size_t asked = 0;
  for (std::size_t d : board.devices) {
    answered_[d] = 0;
    if (book_[d].faulted) continue;
    length +=
        maestro::encode_get_position(board.address, static_cast<std::uint8_t>(channels_[d].channel),
                                     {tx_.data() + length, tx_.size() - length});
    ++asked;
  }
  length += maestro::encode_get_errors(board.address, {tx_.data() + length, tx_.size() - length});
  const std::size_t want = 2 * asked + 2;
  // Late answers of an earlier burst must not pass for this one's: an
  // answer is two bytes with no channel or board in them, and one that came
  // in part before this burst and in part after would shift every value
  // onto the next channel (a position taken for another channel's, then
  // sent to it as its target at activate).
  read_away_owed();
  transport_->discard_input();
  const auto sent = steady_clock::now();
  send(length);
  const std::size_t got = receive(want, timeout_);
  if (got < want) {
    // The rest may still come, as late again as the wait was long.
    const auto now = steady_clock::now();
    owed_bytes_ = want - got;
    owed_until_ = now + (now - sent);
  }

  std::size_t slot = 0;
  for (std::size_t d : board.devices) {
    if (book_[d].faulted) continue;
    if (count) book_.asked(d);
    if (got >= 2 * (slot + 1)) {
      const std::uint16_t position = maestro::decode_answer(&rx_[2 * slot]);
      // 0: the channel is off (no pulses); keep the last known output.
      if (position != 0) present_[d] = position;
      answered_[d] = 1;
      book_.answered(d);
    } else if (count && got > 2 * slot) {
      book_.garbled(d);  // an answer cut short
    } else if (count) {
      book_.timed_out(d);
    }
    ++slot;
  }
  if (got < want) return false;
  const std::uint16_t errors = maestro::decode_answer(&rx_[2 * asked]);
  board.last_errors = errors;
  if (errors != 0 && count) {
    for (std::size_t d : board.devices) {
      if (book_[d].faulted) continue;
      book_.hardware_fault(d, static_cast<std::uint8_t>(errors & 0xFF));
      book_[d].last_error_byte = static_cast<std::uint8_t>(errors >> 8);
    }
  }
  return true;
}

std::uint16_t MaestroBus::target_of(std::size_t device, double rad) const {
  if (!std::isfinite(rad)) return goal_[device];
  const MaestroChannelOptions& ch = channels_[device];
  const double lo = std::ceil(ch.min_us * 4.0);
  const double hi = std::floor(ch.max_us * 4.0);
  const ActuatorBinding& b = config_.actuators[device];
  rad = b.safe_goal(rad, rad);  // into the joint's limits (finite here)
  const double ticks = std::round(b.zero_ticks + b.direction * rad * b.ticks_per_rad);
  return static_cast<std::uint16_t>(std::clamp(ticks, lo, hi));
}

// ---- lifecycle --------------------------------------------------------------

void MaestroBus::configure() {
  book_.reset();
  for (std::size_t i = 0; i < book_.size(); ++i) {
    book_[i].device_id = options_.form == maestro::Form::compact
                             ? channels_[i].channel
                             : 100 * channels_[i].device + channels_[i].channel;
    book_[i].open_loop = true;
    present_[i] = 0;
  }
  std::string silent;
  timeout_warning_.clear();
  for (Board& board : boards_) {
    bool complete = false;
    // The first Get Errors also clears what the board latched before we came
    // (e.g. noise while the line was plugged in, or a serial timeout after
    // the host before us died).
    for (int t = 0; t < kTries && !complete; ++t) complete = poll_board(board, false);
    if (complete && (board.last_errors & maestro::error_bit::serial_timeout) != 0) {
      timeout_warning_ += (timeout_warning_.empty() ? "" : ", ") + std::string("Maestro ") +
                          std::to_string(board.address.device);
    }
    if (complete) complete = poll_board(board, false);
    if (!complete) {
      silent +=
          (silent.empty() ? "" : ", ") + (options_.form == maestro::Form::compact
                                              ? std::string("the board")
                                              : "device " + std::to_string(board.address.device));
      continue;
    }
    if (board.last_errors != 0) {
      throw DeviceError(prefix() + "Maestro " + std::to_string(board.address.device) +
                        " reports errors " + error_names(board.last_errors) +
                        " again after clearing");
    }
  }
  if (transport_->failure() != nullptr) throw DeviceError(prefix() + describe_failure(*transport_));
  if (!silent.empty())
    throw DeviceError(prefix() + "no answer to Get Position/Get Errors from " + silent);
  if (!timeout_warning_.empty()) {
    timeout_warning_ = "serial timeout had fired on " + timeout_warning_ +
                       " (no host talked to it for longer than its timeout: since power-up, or "
                       "a host that died without switching it off); cleared";
    std::fprintf(stderr, "warning: bus %s: %s\n", config_.name.c_str(), timeout_warning_.c_str());
  }
  for (std::size_t i = 0; i < present_.size(); ++i) {
    // A channel that is off has no position: start from the neutral pulse.
    if (present_[i] == 0) {
      const ActuatorBinding& b = config_.actuators[i];
      present_[i] = static_cast<std::uint16_t>(
          std::clamp<double>(b.zero_ticks, std::ceil(channels_[i].min_us * 4.0),
                             std::floor(channels_[i].max_us * 4.0)));
    }
    goal_[i] = present_[i];
  }
  fresh_ = true;
}

void MaestroBus::activate() {
  // A serial timeout shorter than the pause since configure() latched its
  // error and sent the channels home; the targets below switch them on
  // again. Positions read here are of channels about to be set: kept out.
  const std::vector<std::uint16_t> present = present_;
  for (Board& board : boards_) {
    bool complete = false;
    for (int t = 0; t < kTries && !complete; ++t) complete = poll_board(board, false);
    if (complete && (board.last_errors & ~maestro::error_bit::serial_timeout) != 0) {
      const std::string why = "errors " + error_names(board.last_errors);
      present_ = present;
      throw DeviceError(prefix() + "cannot switch on Maestro " +
                        std::to_string(board.address.device) + ": " + why);
    }
  }
  present_ = present;
  for (Board& board : boards_) {
    std::size_t length = 0;
    for (std::size_t d : board.devices) {
      const auto ch = static_cast<std::uint8_t>(channels_[d].channel);
      const std::span<std::uint8_t> rest{tx_.data() + length, tx_.size() - length};
      length += maestro::encode_set_speed(board.address, ch,
                                          static_cast<std::uint16_t>(channels_[d].speed), rest);
      length += maestro::encode_set_acceleration(
          board.address, ch, static_cast<std::uint16_t>(channels_[d].acceleration),
          {tx_.data() + length, tx_.size() - length});
      length += maestro::encode_set_target(board.address, ch, goal_[d],
                                           {tx_.data() + length, tx_.size() - length});
      send(length);
      length = 0;
    }
    bool complete = false;
    for (int t = 0; t < kTries && !complete; ++t) complete = poll_board(board, false);
    if (!complete || board.last_errors != 0) {
      const std::string why =
          complete ? "errors " + error_names(board.last_errors) : std::string("no answer");
      deactivate();
      throw DeviceError(prefix() + "cannot switch on Maestro " +
                        std::to_string(board.address.device) + ": " + why);
    }
  }
}

void MaestroBus::arm_device_guard() {
  const std::vector<std::uint16_t> present = present_;
  for (Board& board : boards_) {
    bool complete = false;
    for (int t = 0; t < kTries && !complete; ++t) complete = poll_board(board, false);
    if (complete && (board.last_errors & maestro::error_bit::serial_timeout) != 0) {
      present_ = present;
      deactivate();
      throw DeviceError(prefix() + "the serial timeout of Maestro " +
                        std::to_string(board.address.device) +
                        " ran out while the other buses came up: set a longer one in the "
                        "Maestro Control Center and in device_watchdog_ms");
    }
  }
  present_ = present;
}

void MaestroBus::deactivate() {
  try {
    for (Board& board : boards_) {
      for (std::size_t d : board.devices) {
        send(maestro::encode_set_target(board.address,
                                        static_cast<std::uint8_t>(channels_[d].channel), 0, tx_));
      }
    }
  } catch (...) {
    // The line is gone; deactivate never throws.
  }
}

// ---- cycle ----------------------------------------------------------------

void MaestroBus::read(std::span<double> positions) {
  const std::size_t n = std::min(positions.size(), book_.size());
  if (fresh_) {
    for (std::size_t i = 0; i < n; ++i) positions[i] = config_.actuators[i].to_rad(present_[i]);
    fresh_ = false;
  }
  for (Board& board : boards_) poll_board(board, true);
  for (std::size_t i = 0; i < n; ++i) {
    if (answered_[i]) positions[i] = config_.actuators[i].to_rad(present_[i]);
  }
}

void MaestroBus::write(std::span<const double> positions) {
  for (Board& board : boards_) {
    std::size_t length = 0;
    std::size_t k = 0;
    const std::size_t count = board.devices.size();
    while (k < count) {
      const std::size_t d = board.devices[k];
      if (book_[d].faulted) {
        ++k;
        continue;
      }
      // A block of consecutive channels, none faulted.
      block_.clear();
      const int first = channels_[d].channel;
      std::size_t e = k;
      while (e < count && !book_[board.devices[e]].faulted &&
             channels_[board.devices[e]].channel == first + static_cast<int>(e - k)) {
        const std::size_t dev = board.devices[e];
        if (dev < positions.size()) goal_[dev] = target_of(dev, positions[dev]);
        block_.push_back(goal_[dev]);
        ++e;
      }
      const std::span<std::uint8_t> rest{tx_.data() + length, tx_.size() - length};
      if (options_.multiple_targets && block_.size() > 1) {
        length += maestro::encode_set_multiple_targets(
            board.address, static_cast<std::uint8_t>(first), block_, rest);
      } else {
        for (std::size_t j = 0; j < block_.size(); ++j) {
          length += maestro::encode_set_target(
              board.address, static_cast<std::uint8_t>(first + static_cast<int>(j)), block_[j],
              {tx_.data() + length, tx_.size() - length});
        }
      }
      k = e;
    }
    send(length);
  }
}

}  // namespace animrt
