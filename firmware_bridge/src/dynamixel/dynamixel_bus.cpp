#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <utility>

#include "animrt/bridge/dynamixel/latency_timer.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

using std::chrono::steady_clock;

// Any data length is fine (ping: the model number layout is not our business).
constexpr std::size_t kAnyLength = std::numeric_limits<std::size_t>::max();
constexpr std::uint8_t kErrorNumberMask = 0x7F;

const char* status_error_name(std::uint8_t number) {
  switch (static_cast<dxl::StatusError>(number)) {
    case dxl::StatusError::none:
      return "none";
    case dxl::StatusError::result_fail:
      return "result fail";
    case dxl::StatusError::instruction:
      return "instruction error";
    case dxl::StatusError::crc:
      return "CRC error";
    case dxl::StatusError::data_range:
      return "data range error";
    case dxl::StatusError::data_length:
      return "data length error";
    case dxl::StatusError::data_limit:
      return "data limit error";
    case dxl::StatusError::access:
      return "access error";
  }
  return "unknown error";
}

std::string hex_byte(std::uint8_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v);
  return buf;
}

// X-series hardware error status register (address 70) bits.
std::string hardware_error_text(std::uint8_t bits) {
  static constexpr std::pair<std::uint8_t, const char*> kBits[] = {
      {0x01, "input voltage"},    {0x04, "overheating"}, {0x08, "motor encoder"},
      {0x10, "electrical shock"}, {0x20, "overload"},
  };
  std::string out = "hardware error status " + hex_byte(bits);
  std::string names;
  for (const auto& [bit, name] : kBits) {
    if ((bits & bit) == 0) continue;
    if (!names.empty()) names += ", ";
    names += name;
  }
  if (!names.empty()) out += ": " + names;
  return out;
}

}  // namespace

DynamixelBus::DynamixelBus(BusConfig config, std::unique_ptr<ByteTransport> transport)
    : config_(std::move(config)),
      transport_(std::move(transport)),
      timeout_(std::chrono::ceil<std::chrono::microseconds>(
          std::chrono::duration<double>(config_.timeout_s))) {
  const std::string bus = "bus " + config_.name + ": ";
  if (!transport_) throw DeviceError(bus + "no transport");
  if (!(config_.timeout_s > 0.0)) throw DeviceError(bus + "timeout must be positive");
  transport_->set_timeout(timeout_);
  const std::size_t n = config_.actuators.size();
  if (n > kMaxDevices) {
    throw DeviceError(bus + std::to_string(n) + " devices do not fit one Sync Write (at most " +
                      std::to_string(kMaxDevices) + ")");
  }
  bool used[256] = {};
  for (const ActuatorBinding& b : config_.actuators) {
    const std::string who = "device id " + std::to_string(b.device_id) + " (" + b.joint + ")";
    if (b.device_id < 0 || b.device_id > 252) throw DeviceError(bus + who + " is outside 0..252");
    if (used[b.device_id]) throw DeviceError(bus + who + " is used twice");
    used[b.device_id] = true;
    if (b.direction != 1 && b.direction != -1) {
      throw DeviceError(bus + who + ": direction must be +1 or -1");
    }
    if (!(b.ticks_per_rad > 0.0) || !std::isfinite(b.ticks_per_rad)) {
      throw DeviceError(bus + who + ": ticks per radian must be positive");
    }
  }

  status_.resize(n);
  present_ticks_.resize(n);
  goal_ticks_.resize(n);
  window_.resize(n);
  alert_seen_.resize(n);
  status_pending_.resize(n);
  ids_.resize(n);
  asked_.resize(n);
  answer_.resize(n);
  suspect_.resize(n);
  value_.resize(n);
  sync_data_.resize(4 * n);
  model_.resize(n);
  firmware_.resize(n);
  fast_mode_ = dxl::bus_options(config_).fast_read;
  watchdog_units_ = dxl::bus_options(config_).bus_watchdog;
  watchdog_time_ = std::chrono::milliseconds(20) * watchdog_units_;
  if (watchdog_units_ > kMaxWatchdogUnits) {
    throw DeviceError(bus + "Bus Watchdog " + std::to_string(watchdog_units_) +
                      " is outside 0..127");
  }
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    status_[i].device_id = b.device_id;
    device_of_id_[static_cast<std::size_t>(b.device_id)] = static_cast<std::int16_t>(i);
    present_ticks_[i] = goal_ticks_[i] = b.zero_ticks;
    // One tick inside the int32 range so rounding cannot wrap.
    window_[i] = GoalWindow::for_joint(b, std::numeric_limits<std::int32_t>::min() + 1,
                                       std::numeric_limits<std::int32_t>::max() - 1);
  }
}

std::string DynamixelBus::prefix() const {
  return "bus " + config_.name + " (" + transport_->port() + "): ";
}

std::string DynamixelBus::describe(std::size_t device) const {
  const ActuatorBinding& b = config_.actuators[device];
  return "id " + std::to_string(b.device_id) + " (" + b.joint + ")";
}

// ---- transactions ---------------------------------------------------------

dxl::DecodeResult DynamixelBus::next_event(dxl::Packet& packet, Deadline deadline) {
  for (;;) {
    if (rx_begin_ < rx_end_) {
      rx_begin_ += decoder_.feed({rx_.data() + rx_begin_, rx_end_ - rx_begin_});
    }
    const dxl::DecodeResult r = decoder_.next(packet);
    if (r != dxl::DecodeResult::need_more) return r;
    if (rx_begin_ < rx_end_) {
      // Full decoder that still sees no packet: drop its bytes, never stall.
      decoder_.reset();
      continue;
    }
    const auto now = steady_clock::now();
    if (now >= deadline) return dxl::DecodeResult::need_more;
    rx_begin_ = 0;
    rx_end_ = transport_->read(rx_, std::chrono::ceil<std::chrono::microseconds>(deadline - now));
    // A failed line answers nothing, at once: no point waiting for the deadline.
    if (rx_end_ == 0 && transport_->failure() != nullptr) return dxl::DecodeResult::need_more;
  }
}

void DynamixelBus::blame(std::size_t slot, bool crc) {
  DeviceStatus& st = status_[asked_[slot]];
  ++(crc ? st.crc_errors : st.protocol_errors);
  st.health = DeviceHealth::protocol_error;
  answer_[slot] = Answer::garbled;
}

void DynamixelBus::accept(std::size_t slot, const dxl::Packet& packet, std::size_t data_length,
                          bool diagnostic) {
  if (packet.params.empty()) {  // a status packet always carries its error byte
    blame(slot, false);
    return;
  }
  accept(slot, packet.params[0], packet.params.subspan(1), data_length, diagnostic);
}

void DynamixelBus::accept(std::size_t slot, std::uint8_t error, std::span<const std::uint8_t> data,
                          std::size_t data_length, bool diagnostic) {
  const std::size_t device = asked_[slot];
  DeviceStatus& st = status_[device];
  const bool alert = (error & dxl::kAlertBit) != 0;
  st.last_error_byte = error;
  if (!diagnostic) {
    if (alert) {
      ++st.hardware_errors;
      // Read the fault register once per episode, not on every cycle.
      if (!alert_seen_[device]) status_pending_[device] = 1;
    }
    alert_seen_[device] = alert ? 1 : 0;
  }
  const bool bad_number = (error & kErrorNumberMask) != 0;
  const bool bad_length = !bad_number && data_length != kAnyLength && data.size() != data_length;
  if (bad_number || bad_length) {
    ++st.protocol_errors;
    st.health = alert ? DeviceHealth::hardware_error : DeviceHealth::protocol_error;
    answer_[slot] = Answer::rejected;
    return;
  }
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < std::min<std::size_t>(4, data.size()); ++i) {
    value |= static_cast<std::uint32_t>(data[i]) << (8 * i);
  }
  value_[slot] = value;
  answer_[slot] = Answer::ok;
  st.health = alert ? DeviceHealth::hardware_error : DeviceHealth::ok;
}

void DynamixelBus::transact(std::size_t length, std::size_t count, std::size_t data_length,
                            bool diagnostic) {
  for (std::size_t s = 0; s < count; ++s) {
    answer_[s] = Answer::pending;
    suspect_[s] = 0;
    ++status_[asked_[s]].transactions;
  }
  // Late answers from an earlier transaction must not pass for this one's.
  transport_->discard_input();
  decoder_.reset();
  rx_begin_ = rx_end_ = 0;
  transport_->write({tx_.data(), length});
  last_sent_ = steady_clock::now();

  const steady_clock::time_point start = steady_clock::now();
  const Deadline cap = start + timeout_ * static_cast<std::int64_t>(count);
  Deadline deadline = std::min(cap, start + timeout_);
  // Each answer (whatever it was) restarts the wait for the next one.
  const auto answered = [&] { deadline = std::min(cap, steady_clock::now() + timeout_); };
  std::size_t remaining = count;
  std::size_t expected = 0;  // first slot still waiting: whose answer comes next
  dxl::Packet packet;
  while (remaining > 0) {
    while (answer_[expected] != Answer::pending) ++expected;
    const dxl::DecodeResult r = next_event(packet, deadline);
    if (r == dxl::DecodeResult::need_more) break;
    if (r == dxl::DecodeResult::bad_crc) {
      // A whole packet arrived damaged: that was the answer, no other follows.
      blame(expected, true);
      --remaining;
      answered();
      continue;
    }
    std::size_t slot = count;
    if (r == dxl::DecodeResult::packet) {
      // Our own instruction, echoed by a half-duplex adapter, is no answer.
      if (packet.instruction != dxl::inst::status) continue;
      slot = expected;
      while (slot < count && !(ids_[slot] == packet.id && answer_[slot] == Answer::pending)) ++slot;
    }
    if (slot < count && stale(packet, data_length)) {
      // Right id, but no answer to this instruction (a late answer to an
      // earlier one, e.g. a ping's 3 bytes when 4 are read): the real answer
      // may still come.
      DeviceStatus& st = status_[asked_[slot]];
      ++st.protocol_errors;
      st.health = DeviceHealth::protocol_error;
      suspect_[slot] = 1;
      continue;
    }
    if (slot == count && r == dxl::DecodeResult::packet && device_of_id_[packet.id] >= 0) {
      // A late answer of another device on this bus (to an earlier request):
      // its own fault, not the fault of the device whose answer is awaited.
      DeviceStatus& st = status_[static_cast<std::size_t>(device_of_id_[packet.id])];
      ++st.protocol_errors;
      continue;
    }
    if (slot == count) {
      // Junk that looked like a header, or a packet from an id not asked (or
      // answered twice): counted, and the real answer is still waited for.
      DeviceStatus& st = status_[asked_[expected]];
      ++st.protocol_errors;
      st.health = DeviceHealth::protocol_error;
      suspect_[expected] = 1;
      continue;
    }
    accept(slot, packet, data_length, diagnostic);
    --remaining;
    answered();
  }

  // Bytes of an unfinished packet at the deadline: the next answer was cut short.
  bool truncated = decoder_.buffered() > 0;
  for (std::size_t s = 0; s < count; ++s) {
    if (answer_[s] != Answer::pending) continue;
    DeviceStatus& st = status_[asked_[s]];
    answer_[s] = Answer::garbled;
    if (suspect_[s] != 0) continue;  // already counted as a protocol error
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

void DynamixelBus::transact_fast(std::size_t length, std::size_t count, std::size_t data_length) {
  for (std::size_t s = 0; s < count; ++s) {
    answer_[s] = Answer::pending;
    suspect_[s] = 0;
    ++status_[asked_[s]].transactions;
  }
  transport_->discard_input();
  decoder_.reset();
  rx_begin_ = rx_end_ = 0;
  transport_->write({tx_.data(), length});
  last_sent_ = steady_clock::now();

  // Collect bytes until the packet the header announces is complete. The
  // packet is not byte-stuffed, so it is read raw, not through the Decoder.
  const steady_clock::time_point start = steady_clock::now();
  const Deadline cap = start + timeout_ * static_cast<std::int64_t>(count);
  Deadline deadline = std::min(cap, start + timeout_);
  const std::size_t slice_size = dxl::kFastSliceOverhead + data_length;
  std::size_t slices = 0;
  std::size_t got = 0;
  for (;;) {
    const dxl::FastStatusReader so_far({fast_rx_.data(), got});
    if (so_far.complete()) break;
    const auto now = steady_clock::now();
    if (so_far.after_header() / slice_size > slices) {
      // Another servo's slice is in: the wait for the next one starts again.
      slices = so_far.after_header() / slice_size;
      deadline = std::min(cap, now + timeout_);
    }
    if (now >= deadline || got == fast_rx_.size()) break;
    const std::size_t n =
        transport_->read({fast_rx_.data() + got, fast_rx_.size() - got},
                         std::chrono::ceil<std::chrono::microseconds>(deadline - now));
    got += n;
    if (n == 0 && transport_->failure() != nullptr) break;
  }

  // Slice by slice: each carries its own CRC, so a damaged or missing slice
  // costs only its device (and, when damaged, the slices behind it).
  dxl::FastStatusReader reader({fast_rx_.data(), got});
  std::size_t expected = 0;  // slots before it have had their turn
  for (;;) {
    std::uint8_t id = 0;
    if (!reader.peek_id(id)) break;
    std::size_t slot = expected;
    while (slot < count && !(ids_[slot] == id && answer_[slot] == Answer::pending)) ++slot;
    if (slot == count) {
      // An id not asked (or twice): its length is unknown, nothing behind it
      // can be read.
      if (expected < count) {
        DeviceStatus& st = status_[asked_[expected]];
        ++st.protocol_errors;
        st.health = DeviceHealth::protocol_error;
        suspect_[expected] = 1;
      }
      break;
    }
    dxl::FastSlice slice;
    const auto step = reader.next(data_length, slice);
    if (step == dxl::FastStatusReader::Step::slice) {
      accept(slot, slice.error, slice.data, data_length, false);
      expected = slot + 1;
      continue;
    }
    if (step == dxl::FastStatusReader::Step::bad_crc ||
        step == dxl::FastStatusReader::Step::short_) {
      blame(slot, step == dxl::FastStatusReader::Step::bad_crc);
    }
    break;
  }
  for (std::size_t s = 0; s < count; ++s) {
    if (answer_[s] != Answer::pending) continue;
    answer_[s] = Answer::garbled;
    if (suspect_[s] != 0) continue;  // already counted as a protocol error
    DeviceStatus& st = status_[asked_[s]];
    ++st.timeouts;
    st.health = DeviceHealth::timeout;
    answer_[s] = Answer::timeout;
  }
}

bool DynamixelBus::stale(const dxl::Packet& packet, std::size_t data_length) {
  if (data_length == kAnyLength || packet.params.empty()) return false;
  // An error number is a verdict on this instruction whatever its length.
  if ((packet.params[0] & kErrorNumberMask) != 0) return false;
  return packet.params.size() - 1 != data_length;
}

DynamixelBus::Answer DynamixelBus::unicast(std::size_t device, std::size_t length,
                                           std::size_t data_length, int tries, bool diagnostic) {
  Answer a = Answer::timeout;
  if (length == 0) return a;
  for (int t = 0; t < tries; ++t) {
    ids_[0] = static_cast<std::uint8_t>(config_.actuators[device].device_id);
    asked_[0] = device;
    transact(length, 1, data_length, diagnostic);  // tx_ still holds the instruction
    a = answer_[0];
    if (a == Answer::ok || a == Answer::rejected) break;  // retrying will not change a verdict
  }
  return a;
}

DynamixelBus::Answer DynamixelBus::write_register(std::size_t device, std::uint16_t address,
                                                  std::uint32_t value, std::uint16_t size,
                                                  int tries) {
  std::uint8_t data[4];
  dxl::put_u32(data, value);
  const auto id = static_cast<std::uint8_t>(config_.actuators[device].device_id);
  const std::size_t length = dxl::encode_write(id, address, {data, size}, tx_);
  return unicast(device, length, 0, tries);
}

void DynamixelBus::read_pending_hardware_status() {
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_pending_[i] == 0) continue;
    status_pending_[i] = 0;
    DeviceStatus& st = status_[i];
    const auto id = static_cast<std::uint8_t>(st.device_id);
    const std::size_t length = dxl::encode_read(id, dxl::xreg::hardware_error_status, 1, tx_);
    // The diagnosis must not overwrite the verdict of the cycle.
    const DeviceHealth health = st.health;
    if (unicast(i, length, 1, 1, true) == Answer::ok) {
      st.hardware_error_status = static_cast<std::uint8_t>(value_[0]);
    }
    st.health = health;
  }
}

std::string DynamixelBus::failure(std::size_t device, Answer answer) const {
  const DeviceStatus& st = status_[device];
  switch (answer) {
    case Answer::timeout:
      return "no answer";
    case Answer::garbled:
      return "garbled answer";
    case Answer::rejected: {
      const std::uint8_t number = st.last_error_byte & kErrorNumberMask;
      if (number == 0) return "answer with the wrong data length";
      return "status error " + hex_byte(st.last_error_byte) + " (" + status_error_name(number) +
             ")";
    }
    case Answer::ok:
    case Answer::pending:
      break;
  }
  return "device reports a hardware error (" + hardware_error_text(st.hardware_error_status) + ")";
}

// ---- lifecycle --------------------------------------------------------------

void DynamixelBus::configure() {
  // A USB adapter's latency timer above 1 ms delays every answer by it.
  latency_warning_ = latency_timer_warning(transport_->port(), sysfs_root_);
  if (!latency_warning_.empty()) {
    std::fprintf(stderr, "warning: bus %s: %s\n", config_.name.c_str(), latency_warning_.c_str());
  }
  const std::size_t n = status_.size();
  for (std::size_t i = 0; i < n; ++i) {
    status_[i] = DeviceStatus{};
    status_[i].device_id = config_.actuators[i].device_id;
    alert_seen_[i] = status_pending_[i] = 0;
  }
  fresh_ = false;

  std::vector<Answer> pinged(n, Answer::timeout);
  ping_until_answered(n, [&](std::size_t i) {
    const auto id = static_cast<std::uint8_t>(status_[i].device_id);
    const Answer a = unicast(i, dxl::encode_ping(id, tx_), kAnyLength);
    if (a == Answer::ok) {  // model number (2 bytes), firmware version
      model_[i] = static_cast<std::uint16_t>(value_[0] & 0xFFFF);
      firmware_[i] = static_cast<std::uint8_t>((value_[0] >> 16) & 0xFF);
    }
    pinged[i] = a;
    return a == Answer::ok || a == Answer::rejected;  // it answered: it is there
  });
  std::string silent, garbled;
  for (std::size_t i = 0; i < n; ++i) {
    if (pinged[i] == Answer::ok || pinged[i] == Answer::rejected) continue;
    std::string& list = pinged[i] == Answer::timeout ? silent : garbled;
    list += (list.empty() ? "" : ", ") + describe(i);
  }
  if (transport_->failure() != nullptr) {
    throw DeviceError(prefix() + describe_failure(*transport_));
  }
  if (!silent.empty() || !garbled.empty()) {
    std::string message = prefix();
    if (!silent.empty()) message += "no answer to ping from " + silent;
    if (!garbled.empty()) {
      message +=
          (silent.empty() ? "" : "; ") + std::string("garbled answer to ping from ") + garbled;
    }
    throw DeviceError(message);
  }

  std::string wrong_model;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint16_t want = dxl::device_options(config_.actuators[i]).model_number;
    if (want == 0 || want == model_[i]) continue;
    const auto name = [](std::uint16_t number) {
      const dxl::XModel* m = dxl::find_x_model(number);
      return m != nullptr ? std::string(m->name) + " (model number " + std::to_string(number) + ")"
                          : "model number " + std::to_string(number);
    };
    wrong_model += (wrong_model.empty() ? "" : "; ") + describe(i) + " is a " + name(model_[i]) +
                   ", the config says " + name(want);
  }
  if (!wrong_model.empty()) throw DeviceError(prefix() + wrong_model);

  std::string unread;
  for (std::size_t i = 0; i < n; ++i) {
    const auto id = static_cast<std::uint8_t>(status_[i].device_id);
    const std::size_t length = dxl::encode_read(id, dxl::xreg::present_position, 4, tx_);
    const Answer a = unicast(i, length, 4);
    if (a == Answer::ok) {
      present_ticks_[i] = goal_ticks_[i] = static_cast<std::int32_t>(value_[0]);
    } else {
      unread += (unread.empty() ? "" : "; ") + describe(i) + ": " + failure(i, a);
    }
  }
  if (!unread.empty()) throw DeviceError(prefix() + "cannot read present position of " + unread);
  clear_bus_watchdogs();
  outside_warning_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    // Goals may lead from where the joint rests to its limits, never farther.
    const std::string outside = window_[i].start_at(config_.actuators[i], present_ticks_[i]);
    if (!outside.empty()) {
      outside_warning_ +=
          (outside_warning_.empty() ? "" : "; ") + describe(i) + " is at " + outside;
    }
    write_position_limits(i);
  }
  if (!outside_warning_.empty()) {
    outside_warning_ = outside_limits_warning(outside_warning_, "position limits");
    std::fprintf(stderr, "warning: bus %s: %s\n", config_.name.c_str(), outside_warning_.c_str());
  }
  choose_fast_read();
  read_pending_hardware_status();
  fresh_ = true;
}

void DynamixelBus::clear_bus_watchdogs() {
  // A run that died with the Bus Watchdog set leaves it counting, or fired
  // (goals refused until it reads 0): either way it starts from 0 here.
  watchdog_warning_.clear();
  for (std::size_t i = 0; i < status_.size(); ++i) {
    const auto id = static_cast<std::uint8_t>(status_[i].device_id);
    Answer r = unicast(i, dxl::encode_read(id, dxl::xreg::bus_watchdog, 1, tx_), 1);
    if (r != Answer::ok || value_[0] == 0) continue;  // older firmware: no such item
    const bool fired = value_[0] == dxl::kBusWatchdogFired;
    r = write_register(i, dxl::xreg::bus_watchdog, 0, 1, kTries);
    if (r != Answer::ok) {
      throw DeviceError(prefix() + "cannot clear the Bus Watchdog of " + describe(i) + ": " +
                        failure(i, r));
    }
    if (fired) watchdog_warning_ += (watchdog_warning_.empty() ? "" : ", ") + describe(i);
  }
  if (!watchdog_warning_.empty()) {
    watchdog_warning_ = "Bus Watchdog had fired on " + watchdog_warning_ +
                        " (the host that drove them stopped talking without switching them "
                        "off); cleared";
    std::fprintf(stderr, "warning: bus %s: %s\n", config_.name.c_str(), watchdog_warning_.c_str());
  }
}

void DynamixelBus::choose_fast_read() {
  fast_ = false;
  const std::size_t n = status_.size();
  if (fast_mode_ == dxl::FastRead::off || n == 0) return;
  if (fast_mode_ == dxl::FastRead::on) {
    fast_ = true;
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!dxl::supports_fast_read(model_[i], firmware_[i])) return;
  }
  // Every servo claims it: one Fast Sync Read of all of them must then work,
  // or the cycle falls back to Sync Read (its counters do not count against
  // the devices: configure() resets nothing after this).
  std::vector<DeviceStatus> before(status_.begin(), status_.end());
  for (std::size_t i = 0; i < n; ++i) {
    ids_[i] = static_cast<std::uint8_t>(status_[i].device_id);
    asked_[i] = i;
  }
  const std::size_t length =
      dxl::encode_fast_sync_read(dxl::xreg::present_position, 4, {ids_.data(), n}, tx_);
  if (length > 0) {
    transact_fast(length, n, 4);
    fast_ = std::all_of(answer_.begin(), answer_.begin() + static_cast<std::ptrdiff_t>(n),
                        [](Answer a) { return a == Answer::ok; });
  }
  std::copy(before.begin(), before.end(), status_.begin());
}

void DynamixelBus::write_position_limits(std::size_t device) {
  const ActuatorBinding& b = config_.actuators[device];
  if (!b.has_limits()) return;
  // The joint's limits in ticks, widened to the measured position of a joint
  // that rests outside them (else the servo would refuse to hold it there:
  // Data Limit Error), inside the range X-series position mode accepts
  // (0..4095).
  const std::int32_t a = b.to_ticks(b.min_position);
  const std::int32_t c = b.to_ticks(b.max_position);
  const std::int32_t at = present_ticks_[device];
  const auto lo = static_cast<std::uint32_t>(std::clamp(std::min({a, c, at}), 0, kXMaxTicks));
  const auto hi = static_cast<std::uint32_t>(std::clamp(std::max({a, c, at}), 0, kXMaxTicks));
  const auto id = static_cast<std::uint8_t>(b.device_id);
  const auto fail = [&](Answer answer, const std::string& what) {
    throw DeviceError(prefix() + "cannot " + what + " of " + describe(device) + ": " +
                      failure(device, answer));
  };
  std::uint32_t now_lo = 0, now_hi = 0;
  Answer r = unicast(device, dxl::encode_read(id, dxl::xreg::max_position_limit, 4, tx_), 4);
  if (r != Answer::ok) fail(r, "read Max Position Limit");
  now_hi = value_[0];
  r = unicast(device, dxl::encode_read(id, dxl::xreg::min_position_limit, 4, tx_), 4);
  if (r != Answer::ok) fail(r, "read Min Position Limit");
  now_lo = value_[0];
  if (now_lo == lo && now_hi == hi) return;  // EEPROM: written only when it differs
  // EEPROM items are locked while torque is on.
  r = unicast(device, dxl::encode_read(id, dxl::xreg::torque_enable, 1, tx_), 1);
  if (r != Answer::ok) fail(r, "read Torque Enable");
  if (value_[0] != 0) {
    r = write_register(device, dxl::xreg::torque_enable, 0, 1, kTries);
    if (r != Answer::ok) fail(r, "turn torque off to write the position limits");
  }
  r = write_register(device, dxl::xreg::max_position_limit, hi, 4, kTries);
  if (r != Answer::ok) fail(r, "write Max Position Limit " + std::to_string(hi));
  r = write_register(device, dxl::xreg::min_position_limit, lo, 4, kTries);
  if (r != Answer::ok) fail(r, "write Min Position Limit " + std::to_string(lo));
}

void DynamixelBus::activate() {
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_[i].faulted) continue;
    // Goal = where the servo is, so torque on cannot jump to a stale goal.
    const std::int32_t ticks = present_ticks_[i];
    const auto check = [&](Answer a, const char* action) {
      if (a == Answer::ok && alert_seen_[i] == 0) return;
      // A servo in hardware error shutdown would stay limp: refuse to start.
      if (a == Answer::ok) read_pending_hardware_status();
      const std::string message =
          prefix() + "cannot " + action + " of " + describe(i) + ": " + failure(i, a);
      deactivate();
      throw DeviceError(message);
    };
    check(write_register(i, dxl::xreg::goal_position, static_cast<std::uint32_t>(ticks), 4, kTries),
          "write goal position");
    goal_ticks_[i] = ticks;
    check(write_register(i, dxl::xreg::torque_enable, 1, 1, kTries), "enable torque");
  }
}

void DynamixelBus::arm_device_guard() {
  if (watchdog_units_ == 0) return;
  // After torque on: a servo watches the line only while torque is on.
  broadcast_bus_watchdog();
  std::string unset;
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_[i].faulted) continue;
    const auto id = static_cast<std::uint8_t>(status_[i].device_id);
    const Answer r = unicast(i, dxl::encode_read(id, dxl::xreg::bus_watchdog, 1, tx_), 1);
    if (r != Answer::ok || value_[0] != watchdog_units_) {
      unset += (unset.empty() ? "" : ", ") + describe(i) + ": " +
               (r == Answer::ok ? "reads " + std::to_string(value_[0]) : failure(i, r));
    }
  }
  if (!unset.empty()) {
    deactivate();
    throw DeviceError(prefix() + "cannot set the Bus Watchdog (firmware 38 or later; or " +
                      "device_watchdog_ms: off) of " + unset);
  }
  // The reads above fed only the servo each was for: start every servo's
  // time again together.
  broadcast_bus_watchdog();
  last_answered_ = last_sent_;
  armed_ = true;
}

void DynamixelBus::broadcast_bus_watchdog() {
  // 0 first: a guard that fired (255) takes a new time only from 0.
  for (const std::uint8_t value : {std::uint8_t{0}, watchdog_units_}) {
    const std::size_t length =
        dxl::encode_write(dxl::kBroadcastId, dxl::xreg::bus_watchdog, {&value, 1}, tx_);
    if (length > 0) transport_->write({tx_.data(), length});
  }
  last_sent_ = steady_clock::now();
}

void DynamixelBus::deactivate() {
  armed_ = false;
  try {
    for (std::size_t i = 0; i < status_.size(); ++i) {
      // Before torque off, so a clean stop leaves no guard armed (and clears
      // one that fired). Not for a device the cycle left out: a silent one
      // would only delay its torque-off; the next configure clears it.
      if (watchdog_units_ > 0 && !status_[i].faulted) {
        write_register(i, dxl::xreg::bus_watchdog, 0, 1, kTries);
      }
      write_register(i, dxl::xreg::torque_enable, 0, 1, kTries);
    }
  } catch (...) {
    // The line is gone: nothing more can be sent, and deactivate never throws.
  }
}

// ---- cycle ----------------------------------------------------------------

void DynamixelBus::read(std::span<double> positions) {
  const std::size_t n = std::min(status_.size(), positions.size());
  if (fresh_) {
    // Hand out what configure() read, so no entry starts undefined.
    for (std::size_t i = 0; i < n; ++i) {
      positions[i] = config_.actuators[i].to_rad(present_ticks_[i]);
    }
    fresh_ = false;
  }
  rearm_after_silence();
  std::size_t count = 0;
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_[i].faulted) continue;
    ids_[count] = static_cast<std::uint8_t>(status_[i].device_id);
    asked_[count] = i;
    ++count;
  }
  if (count > 0) {
    const std::size_t length =
        fast_
            ? dxl::encode_fast_sync_read(dxl::xreg::present_position, 4, {ids_.data(), count}, tx_)
            : dxl::encode_sync_read(dxl::xreg::present_position, 4, {ids_.data(), count}, tx_);
    if (length > 0) {
      if (fast_) {
        transact_fast(length, count, 4);
      } else {
        transact(length, count, 4, false);
      }
      for (std::size_t s = 0; s < count; ++s) {
        if (answer_[s] != Answer::ok) continue;
        last_answered_ = steady_clock::now();
        const std::size_t i = asked_[s];
        present_ticks_[i] = static_cast<std::int32_t>(value_[s]);
        if (i < n) positions[i] = config_.actuators[i].to_rad(present_ticks_[i]);
      }
    }
  }
  // Only after an alert appeared: one extra transaction in that failure case.
  read_pending_hardware_status();
}

std::int32_t DynamixelBus::goal_ticks(std::size_t device, double rad) const {
  if (!std::isfinite(rad)) return goal_ticks_[device];  // hold the last goal
  return config_.actuators[device].to_ticks(window_[device].clamp(rad));
}

void DynamixelBus::write(std::span<const double> positions) {
  rearm_after_silence();
  std::size_t count = 0;
  for (std::size_t i = 0; i < status_.size(); ++i) {
    if (status_[i].faulted) continue;
    if (i < positions.size()) {
      goal_ticks_[i] = goal_ticks(i, positions[i]);
      if (std::isfinite(positions[i])) window_[i].narrow(positions[i]);
    }
    ids_[count] = static_cast<std::uint8_t>(status_[i].device_id);
    dxl::put_u32(sync_data_.data() + 4 * count, static_cast<std::uint32_t>(goal_ticks_[i]));
    ++count;
  }
  if (count == 0) return;
  const std::size_t length = dxl::encode_sync_write(
      dxl::xreg::goal_position, 4, {ids_.data(), count}, {sync_data_.data(), 4 * count}, tx_);
  if (length > 0) {
    transport_->write({tx_.data(), length});
    last_sent_ = steady_clock::now();
  }
}

void DynamixelBus::rearm_after_silence() {
  if (!armed_) return;
  const auto now = steady_clock::now();
  // Half the guard's time: the servos' clocks and ours need not agree on
  // when it ran out. Silent either way: nothing sent (the host stalled), or
  // nothing heard (what was sent sat in a kernel or adapter buffer, and the
  // servos heard nothing either).
  const auto half = watchdog_time_ / 2;
  if (now - last_sent_ <= half && now - last_answered_ <= half) return;
  // So the guard may have fired: the servos stopped and refuse goals.
  // Broadcast, so no answers to wait for.
  broadcast_bus_watchdog();
  ++watchdog_rearms_;
}

}  // namespace animrt
