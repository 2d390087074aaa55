#include "animrt/bridge/feetech/feetech_bus.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <utility>

#include "animrt/core/error.hpp"

namespace animrt {
namespace {

using std::chrono::steady_clock;

constexpr std::size_t kAnyLength = std::numeric_limits<std::size_t>::max();

std::string hex_byte(std::uint8_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v);
  return buf;
}

std::string error_text(std::uint8_t bits) {
  static constexpr std::pair<std::uint8_t, const char*> kBits[] = {
      {ft::error_bit::voltage, "voltage"},
      {ft::error_bit::sensor, "sensor"},
      {ft::error_bit::temperature, "temperature"},
      {ft::error_bit::current, "current"},
      {ft::error_bit::angle, "angle"},
      {ft::error_bit::overload, "overload"},
  };
  std::string out = "servo status " + hex_byte(bits);
  std::string names;
  for (const auto& [bit, name] : kBits) {
    if ((bits & bit) == 0) continue;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  if (!names.empty()) out += ": " + names;
  return out;
}

}  // namespace

FeetechBus::FeetechBus(BusConfig config, ft::Series series,
                       std::unique_ptr<ByteTransport> transport)
    : config_(std::move(config)),
      series_(series),
      transport_(std::move(transport)),
      timeout_(std::chrono::ceil<std::chrono::microseconds>(
          std::chrono::duration<double>(config_.timeout_s))),
      // STS positions are sign-magnitude (bit 15), SCS positions unsigned.
      min_ticks_(series == ft::Series::sts ? -((1 << ft::kStsSignBit) - 1) : 0),
      max_ticks_(series == ft::Series::sts ? (1 << ft::kStsSignBit) - 1 : ft::kScsMaxPosition) {
  const std::string bus = "bus " + config_.name + ": ";
  if (!transport_) throw DeviceError(bus + "no transport");
  if (!(config_.timeout_s > 0.0)) throw DeviceError(bus + "timeout must be positive");
  transport_->set_timeout(timeout_);
  const std::size_t n = config_.actuators.size();
  if (n > kMaxDevices) {
    throw DeviceError(bus + std::to_string(n) + " servos do not fit one Sync Write (at most " +
                      std::to_string(kMaxDevices) + ")");
  }
  device_of_id_.fill(-1);
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    const std::string who = "servo id " + std::to_string(b.device_id) + " (" + b.joint + ")";
    if (b.device_id < 0 || b.device_id > ft::kMaxDeviceId) {
      throw DeviceError(bus + who + " is outside 0.." + std::to_string(ft::kMaxDeviceId));
    }
    if (device_of_id_[static_cast<std::size_t>(b.device_id)] >= 0) {
      throw DeviceError(bus + who + " is used twice");
    }
    if (b.direction != 1 && b.direction != -1) {
      throw DeviceError(bus + who + ": direction must be +1 or -1");
    }
    if (!(b.ticks_per_rad > 0.0) || !std::isfinite(b.ticks_per_rad)) {
      throw DeviceError(bus + who + ": ticks per radian must be positive");
    }
    device_of_id_[static_cast<std::size_t>(b.device_id)] = static_cast<std::int16_t>(i);
  }
  status_.resize(n);
  present_ticks_.resize(n);
  goal_ticks_.resize(n);
  window_.resize(n);
  ids_.resize(n);
  asked_.resize(n);
  answer_.resize(n);
  suspect_.resize(n);
  value_.resize(n);
  sync_data_.resize(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    status_[i].device_id = b.device_id;
    present_ticks_[i] = goal_ticks_[i] = b.zero_ticks;
    window_[i] = GoalWindow::for_joint(b, min_ticks_, max_ticks_);
  }
}

std::string FeetechBus::prefix() const {
  return "bus " + config_.name + " (" + transport_->port() + "): ";
}

std::string FeetechBus::describe(std::size_t device) const {
  const ActuatorBinding& b = config_.actuators[device];
  return "id " + std::to_string(b.device_id) + " (" + b.joint + ")";
}

std::int32_t FeetechBus::to_position(std::uint16_t raw) const {
  return series_ == ft::Series::sts ? ft::decode_signed(raw, ft::kStsSignBit) : raw;
}

std::uint16_t FeetechBus::from_position(std::int32_t ticks) const {
  const std::int32_t t = std::clamp(ticks, min_ticks_, max_ticks_);
  return series_ == ft::Series::sts ? ft::encode_signed(t, ft::kStsSignBit)
                                    : static_cast<std::uint16_t>(t);
}

// ---- transactions ---------------------------------------------------------

ft::DecodeResult FeetechBus::next_event(ft::Packet& packet, Deadline deadline) {
  for (;;) {
    if (rx_begin_ < rx_end_) {
      rx_begin_ += decoder_.feed({rx_.data() + rx_begin_, rx_end_ - rx_begin_});
    }
    const ft::DecodeResult r = decoder_.next(packet);
    if (r != ft::DecodeResult::need_more) return r;
    if (rx_begin_ < rx_end_) {
      decoder_.reset();  // full decoder that still sees no packet: never stall
      continue;
    }
    const auto now = steady_clock::now();
    std::chrono::microseconds wait{0};
    if (now < deadline) {
      wait = std::chrono::ceil<std::chrono::microseconds>(deadline - now);
    } else if (late_read_done_) {
      return ft::DecodeResult::need_more;
    } else {
      // Past the deadline, one last look without waiting: an answer already
      // queued while this thread was not running is not a timeout.
      late_read_done_ = true;
    }
    rx_begin_ = 0;
    rx_end_ = transport_->read(rx_, wait);
    if (rx_end_ == 0 && (wait.count() == 0 || transport_->failure() != nullptr)) {
      return ft::DecodeResult::need_more;
    }
  }
}

void FeetechBus::blame(std::size_t slot, bool checksum) {
  DeviceStatus& st = status_[asked_[slot]];
  ++(checksum ? st.crc_errors : st.protocol_errors);
  st.health = DeviceHealth::protocol_error;
  answer_[slot] = Answer::garbled;
}

void FeetechBus::accept(std::size_t slot, const ft::Packet& packet) {
  DeviceStatus& st = status_[asked_[slot]];
  const std::uint8_t error = packet.code;
  st.last_error_byte = error;
  if (error != 0) {
    ++st.hardware_errors;
    st.hardware_error_status = error;
    st.health = DeviceHealth::hardware_error;
  } else {
    st.health = DeviceHealth::ok;
  }
  value_[slot] = packet.params.size() >= 2 ? ft::get_u16(series_, packet.params.data()) : 0;
  answer_[slot] = Answer::ok;
}

void FeetechBus::transact(std::size_t length, std::size_t count, std::size_t data_length) {
  for (std::size_t s = 0; s < count; ++s) {
    answer_[s] = Answer::pending;
    suspect_[s] = 0;
    ++status_[asked_[s]].transactions;
  }
  transport_->discard_input();  // late answers must not pass for this one's
  decoder_.reset();
  rx_begin_ = rx_end_ = 0;
  late_read_done_ = false;
  tx_length_ = length;
  transport_->write({tx_.data(), length});

  const Deadline deadline = steady_clock::now() + timeout_;
  std::size_t remaining = count;
  std::size_t expected = 0;
  ft::Packet packet;
  while (remaining > 0) {
    while (answer_[expected] != Answer::pending) ++expected;
    const ft::DecodeResult r = next_event(packet, deadline);
    if (r == ft::DecodeResult::need_more) break;
    if (r == ft::DecodeResult::bad_checksum) {
      blame(expected, true);  // a damaged answer: no other follows from that servo
      --remaining;
      continue;
    }
    if (r == ft::DecodeResult::malformed) {
      DeviceStatus& st = status_[asked_[expected]];
      ++st.protocol_errors;
      st.health = DeviceHealth::protocol_error;
      suspect_[expected] = 1;
      continue;
    }
    // A half-duplex adapter echoes our own instruction: no answer. Nor is
    // anything from the broadcast id (an echo of an earlier broadcast).
    if (packet.id == ft::kBroadcastId ||
        (packet.raw.size() == tx_length_ &&
         std::memcmp(packet.raw.data(), tx_.data(), tx_length_) == 0)) {
      continue;
    }
    std::size_t slot = expected;
    while (slot < count && !(ids_[slot] == packet.id && answer_[slot] == Answer::pending)) ++slot;
    const bool right_length = data_length == kAnyLength || packet.params.size() == data_length;
    if (slot == count || !right_length) {
      // A late answer to an earlier request, another servo's, or junk: counted
      // against the servo it came from (or the one awaited), and the real
      // answer is still waited for.
      const std::int16_t owner = device_of_id_[packet.id];
      const std::size_t blamed =
          slot < count ? asked_[slot]
                       : (owner >= 0 ? static_cast<std::size_t>(owner) : asked_[expected]);
      ++status_[blamed].protocol_errors;
      if (slot < count) {
        status_[blamed].health = DeviceHealth::protocol_error;
        suspect_[slot] = 1;
      }
      continue;
    }
    accept(slot, packet);
    --remaining;
  }

  bool truncated = decoder_.buffered() > 0;
  for (std::size_t s = 0; s < count; ++s) {
    if (answer_[s] != Answer::pending) continue;
    DeviceStatus& st = status_[asked_[s]];
    answer_[s] = Answer::garbled;
    if (suspect_[s] != 0) continue;
    if (truncated) {
      truncated = false;
      ++st.protocol_errors;
      st.health = DeviceHealth::protocol_error;
      continue;
    }
    ++st.timeouts;
    st.health = DeviceHealth::timeout;
    answer_[s] = Answer::timeout;
  }
}

FeetechBus::Answer FeetechBus::unicast(std::size_t device, std::size_t length,
                                       std::size_t data_length, int tries) {
  Answer a = Answer::timeout;
  if (length == 0) return a;
  for (int t = 0; t < tries; ++t) {
    ids_[0] = static_cast<std::uint8_t>(config_.actuators[device].device_id);
    asked_[0] = device;
    transact(length, 1, data_length);  // tx_ still holds the instruction
    a = answer_[0];
    if (a == Answer::ok) break;
  }
  return a;
}

FeetechBus::Answer FeetechBus::write_byte(std::size_t device, std::uint8_t address,
                                          std::uint8_t value) {
  const auto id = static_cast<std::uint8_t>(config_.actuators[device].device_id);
  return unicast(device, ft::encode_write(id, address, {&value, 1}, tx_), 0);
}

FeetechBus::Answer FeetechBus::write_goal(std::size_t device, std::int32_t ticks) {
  std::uint8_t data[2];
  ft::put_u16(series_, data, from_position(ticks));
  const auto id = static_cast<std::uint8_t>(config_.actuators[device].device_id);
  return unicast(device, ft::encode_write(id, ft::reg::goal_position, data, tx_), 0);
}

std::string FeetechBus::failure(std::size_t device, Answer answer) const {
  switch (answer) {
    case Answer::timeout:
      return "no answer";
    case Answer::garbled:
      return "garbled answer";
    case Answer::ok:
    case Answer::pending:
      break;
  }
  return "servo reports a fault (" + error_text(status_[device].last_error_byte) + ")";
}

// ---- lifecycle --------------------------------------------------------------

void FeetechBus::configure() {
  const std::size_t n = status_.size();
  for (std::size_t i = 0; i < n; ++i) {
    status_[i] = DeviceStatus{};
    status_[i].device_id = config_.actuators[i].device_id;
  }
  fresh_ = false;

  std::vector<Answer> pinged(n, Answer::timeout);
  ping_until_answered(n, [&](std::size_t i) {
    const auto id = static_cast<std::uint8_t>(status_[i].device_id);
    pinged[i] = unicast(i, ft::encode_ping(id, tx_), kAnyLength);
    return pinged[i] == Answer::ok;
  });
  std::string silent, garbled;
  for (std::size_t i = 0; i < n; ++i) {
    if (pinged[i] == Answer::ok) continue;
    std::string& list = pinged[i] == Answer::timeout ? silent : garbled;
    list += (list.empty() ? "" : ", ") + describe(i);
  }
  if (transport_->failure() != nullptr) throw DeviceError(prefix() + describe_failure(*transport_));
  if (!silent.empty() || !garbled.empty()) {
    std::string message = prefix();
    if (!silent.empty()) message += "no answer to ping from " + silent;
    if (!garbled.empty()) {
      message +=
          (silent.empty() ? "" : "; ") + std::string("garbled answer to ping from ") + garbled;
    }
    throw DeviceError(message);
  }
  std::string unread;
  for (std::size_t i = 0; i < n; ++i) {
    const auto id = static_cast<std::uint8_t>(status_[i].device_id);
    const Answer a = unicast(i, ft::encode_read(id, ft::reg::present_position, 2, tx_), 2);
    if (a == Answer::ok) {
      present_ticks_[i] = goal_ticks_[i] = to_position(value_[0]);
    } else {
      unread += (unread.empty() ? "" : "; ") + describe(i) + ": " + failure(i, a);
    }
  }
  if (!unread.empty()) throw DeviceError(prefix() + "cannot read present position of " + unread);
  outside_warning_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const std::string outside = window_[i].start_at(config_.actuators[i], present_ticks_[i]);
    if (!outside.empty()) {
      outside_warning_ +=
          (outside_warning_.empty() ? "" : "; ") + describe(i) + " is at " + outside;
    }
    write_angle_limits(i);
  }
  if (!outside_warning_.empty()) {
    outside_warning_ = outside_limits_warning(outside_warning_, "angle limits");
    std::fprintf(stderr, "warning: bus %s: %s\n", config_.name.c_str(), outside_warning_.c_str());
  }
  fresh_ = true;
}

void FeetechBus::write_angle_limits(std::size_t device) {
  const ActuatorBinding& b = config_.actuators[device];
  if (!b.has_limits()) return;
  // The joint's limits in steps, widened to where a joint resting outside
  // them is (else torque on would snap it to a limit), inside the
  // position-mode range.
  const std::int32_t top = series_ == ft::Series::sts ? ft::kStsMaxPosition : ft::kScsMaxPosition;
  const std::int32_t a = b.to_ticks(b.min_position);
  const std::int32_t c = b.to_ticks(b.max_position);
  const std::int32_t at = present_ticks_[device];
  const auto lo = static_cast<std::uint16_t>(std::clamp(std::min({a, c, at}), 0, top));
  const auto hi = static_cast<std::uint16_t>(std::clamp(std::max({a, c, at}), 0, top));
  const auto id = static_cast<std::uint8_t>(b.device_id);
  const auto fail = [&](Answer answer, const std::string& what) {
    throw DeviceError(prefix() + "cannot " + what + " of " + describe(device) + ": " +
                      failure(device, answer));
  };
  Answer r = unicast(device, ft::encode_read(id, ft::reg::min_angle_limit, 2, tx_), 2);
  if (r != Answer::ok) fail(r, "read Min Angle Limit");
  const std::uint16_t now_lo = value_[0];
  r = unicast(device, ft::encode_read(id, ft::reg::max_angle_limit, 2, tx_), 2);
  if (r != Answer::ok) fail(r, "read Max Angle Limit");
  if (now_lo == lo && value_[0] == hi) return;  // EEPROM: written only when it differs
  // EEPROM writes persist only while the lock flag is 0; lock it again after.
  const std::uint8_t lock = series_ == ft::Series::sts ? ft::reg::sts_lock : ft::reg::scs_lock;
  r = write_byte(device, lock, 0);
  if (r != Answer::ok) fail(r, "unlock the EEPROM");
  std::uint8_t data[4];
  ft::put_u16(series_, data, lo);
  ft::put_u16(series_, data + 2, hi);
  r = unicast(device, ft::encode_write(id, ft::reg::min_angle_limit, data, tx_), 0);
  if (r != Answer::ok)
    fail(r, "write Min/Max Angle Limit " + std::to_string(lo) + ".." + std::to_string(hi));
  r = write_byte(device, lock, 1);
  if (r != Answer::ok) fail(r, "lock the EEPROM");
}

void FeetechBus::activate() {
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_[i].faulted) continue;
    const auto check = [&](Answer a, const char* action) {
      if (a == Answer::ok && status_[i].last_error_byte == 0) return;
      // A servo that reports a fault (overload, temperature...) stays limp
      // or cuts out: refuse to start.
      const std::string message =
          prefix() + "cannot " + action + " of " + describe(i) + ": " + failure(i, a);
      deactivate();
      throw DeviceError(message);
    };
    // Goal = where the servo is, so torque on cannot jump to a stale goal.
    check(write_goal(i, present_ticks_[i]), "write goal position");
    goal_ticks_[i] = present_ticks_[i];
    check(write_byte(i, ft::reg::torque_enable, 1), "enable torque");
  }
}

void FeetechBus::deactivate() {
  try {
    for (std::size_t i = 0; i < status_.size(); ++i) write_byte(i, ft::reg::torque_enable, 0);
  } catch (...) {
    // The line is gone; deactivate never throws.
  }
}

// ---- cycle ----------------------------------------------------------------

void FeetechBus::read_positions(std::size_t count) {
  if (series_ == ft::Series::sts) {
    const std::size_t length =
        ft::encode_sync_read(ft::reg::present_position, 2, {ids_.data(), count}, tx_);
    if (length > 0) transact(length, count, 2);
    return;
  }
  // SCS servos have no Sync Read: one Read each, in turn, each with its own
  // timeout. transact() works on slot 0, so each servo is swapped there
  // while it is asked, and its result moved back to its own slot.
  Answer first_answer = Answer::timeout;
  std::uint16_t first_value = 0;
  for (std::size_t s = 0; s < count; ++s) {
    const std::size_t length = ft::encode_read(ids_[s], ft::reg::present_position, 2, tx_);
    std::swap(ids_[0], ids_[s]);
    std::swap(asked_[0], asked_[s]);
    transact(length, 1, 2);
    std::swap(ids_[0], ids_[s]);
    std::swap(asked_[0], asked_[s]);
    if (s == 0) {
      first_answer = answer_[0];
      first_value = value_[0];
    } else {
      answer_[s] = answer_[0];
      value_[s] = value_[0];
    }
  }
  answer_[0] = first_answer;
  value_[0] = first_value;
}

void FeetechBus::read(std::span<double> positions) {
  const std::size_t n = std::min(status_.size(), positions.size());
  if (fresh_) {
    for (std::size_t i = 0; i < n; ++i)
      positions[i] = config_.actuators[i].to_rad(present_ticks_[i]);
    fresh_ = false;
  }
  std::size_t count = 0;
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_[i].faulted) continue;
    ids_[count] = static_cast<std::uint8_t>(status_[i].device_id);
    asked_[count] = i;
    ++count;
  }
  if (count == 0) return;
  read_positions(count);
  for (std::size_t s = 0; s < count; ++s) {
    if (answer_[s] != Answer::ok) continue;
    const std::size_t i = asked_[s];
    present_ticks_[i] = to_position(value_[s]);
    if (i < n) positions[i] = config_.actuators[i].to_rad(present_ticks_[i]);
  }
}

std::int32_t FeetechBus::goal_ticks(std::size_t device, double rad) const {
  if (!std::isfinite(rad)) return goal_ticks_[device];
  return config_.actuators[device].to_ticks(window_[device].clamp(rad));
}

void FeetechBus::write(std::span<const double> positions) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_[i].faulted) continue;
    if (i < positions.size()) {
      goal_ticks_[i] = goal_ticks(i, positions[i]);
      if (std::isfinite(positions[i])) window_[i].narrow(positions[i]);
    }
    ids_[count] = static_cast<std::uint8_t>(status_[i].device_id);
    ft::put_u16(series_, sync_data_.data() + 2 * count, from_position(goal_ticks_[i]));
    ++count;
  }
  if (count == 0) return;
  const std::size_t length = ft::encode_sync_write(ft::reg::goal_position, 2, {ids_.data(), count},
                                                   {sync_data_.data(), 2 * count}, tx_);
  if (length > 0) transport_->write({tx_.data(), length});
}

}  // namespace animrt
