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

using servo::Answer;
// Any data length is fine (ping: the model number layout is not our business).
constexpr std::size_t kAnyLength = servo::kAnyLength;
constexpr std::uint8_t kErrorNumberMask = dxl::LinkCodec::kErrorNumberMask;

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

using servo::hex_byte;

// X-series hardware error status register (address 70) bits.
std::string hardware_error_text(std::uint8_t bits) {
  static constexpr servo::FaultBit kBits[] = {
      {0x01, "input voltage"},    {0x04, "overheating"}, {0x08, "motor encoder"},
      {0x10, "electrical shock"}, {0x20, "overload"},
  };
  return servo::fault_text("hardware error status", bits, kBits);
}

// The registers mapped into Indirect Data 1.. (Indirect Address 1..): the
// position first, so one read of the region carries a cycle, then what the
// health record needs.
constexpr std::uint16_t kPresentCurrent = 126;       // 2, signed
constexpr std::uint16_t kPresentInputVoltage = 144;  // 2, 0.1 V
constexpr std::uint16_t kHealthMap[] = {
    dxl::xreg::present_position,
    dxl::xreg::present_position + 1,
    dxl::xreg::present_position + 2,
    dxl::xreg::present_position + 3,
    kPresentCurrent,
    kPresentCurrent + 1,
    kPresentInputVoltage,
    kPresentInputVoltage + 1,
    dxl::xreg::present_temperature,
    dxl::xreg::hardware_error_status,
};
constexpr std::uint16_t kPackedLength = std::size(kHealthMap);  // 10
constexpr std::uint16_t kHealthOffset = 4;                      // after the position
constexpr std::uint16_t kHealthLength = kPackedLength - kHealthOffset;

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

DynamixelBus::DynamixelBus(BusConfig config, std::unique_ptr<ByteTransport> transport)
    : config_(std::move(config)), link_(config_, std::move(transport), dxl::LinkCodec{}) {
  servo::check_bindings(config_, 252, kMaxDevices);
  const std::size_t n = config_.actuators.size();
  sync_data_.resize(4 * n);
  model_.resize(n);
  firmware_.resize(n);
  current_unit_.resize(n);
  off_pending_.resize(n);
  fast_mode_ = dxl::bus_options(config_).fast_read;
  health_ = dxl::bus_options(config_).health;
  watchdog_units_ = dxl::bus_options(config_).bus_watchdog;
  watchdog_time_ = std::chrono::milliseconds(20) * watchdog_units_;
  if (watchdog_units_ > kMaxWatchdogUnits) {
    throw DeviceError("bus " + config_.name + ": Bus Watchdog " + std::to_string(watchdog_units_) +
                      " is outside 0..127");
  }
  // One tick inside the int32 range so rounding cannot wrap.
  positions_.init(config_, std::numeric_limits<std::int32_t>::min() + 1,
                  std::numeric_limits<std::int32_t>::max() - 1);
}

// ---- transactions ---------------------------------------------------------

void DynamixelBus::transact_fast(std::size_t length, std::size_t count, std::size_t data_length) {
  link_.begin(length, count);
  // Collect bytes until the packet the header announces is complete. The
  // packet is not byte-stuffed, so it is read raw, not through the Decoder.
  servo::AnswerClock clock(link_.timeout(), count);
  const std::size_t slice_size = dxl::kFastSliceOverhead + data_length;
  std::size_t slices = 0;
  const std::size_t got =
      link_.read_raw(fast_rx_, 0, clock, [&](std::span<const std::uint8_t> bytes) {
        const dxl::FastStatusReader so_far(bytes);
        if (so_far.after_header() / slice_size > slices) {
          // Another servo's slice is in: the wait for the next one starts again.
          slices = so_far.after_header() / slice_size;
          clock.answered();
        }
        return so_far.complete();
      });

  // Slice by slice: each carries its own CRC, so a damaged or missing slice
  // costs only its device (and, when damaged, the slices behind it).
  dxl::FastStatusReader reader({fast_rx_.data(), got});
  std::size_t expected = 0;  // slots before it have had their turn
  const auto ids = link_.ids();
  for (;;) {
    std::uint8_t id = 0;
    if (!reader.peek_id(id)) break;
    std::size_t slot = expected;
    while (slot < count && !(ids[slot] == id && link_.answer(slot) == Answer::pending)) ++slot;
    if (slot == count) {
      // An id not asked (or twice): its length is unknown, nothing behind it
      // can be read.
      if (expected < count) link_.suspect(expected);
      break;
    }
    dxl::FastSlice slice;
    const auto step = reader.next(data_length, slice);
    if (step == dxl::FastStatusReader::Step::slice) {
      link_.judge(slot, slice.error, slice.data, data_length, false);
      expected = slot + 1;
      continue;
    }
    if (step == dxl::FastStatusReader::Step::bad_crc ||
        step == dxl::FastStatusReader::Step::short_) {
      link_.blame(slot, step == dxl::FastStatusReader::Step::bad_crc);
    }
    break;
  }
  link_.settle(count, false);
}

Answer DynamixelBus::write_register(std::size_t device, std::uint16_t address, std::uint32_t value,
                                    std::uint16_t size, int tries) {
  std::uint8_t data[4];
  dxl::put_u32(data, value);
  const std::size_t length =
      dxl::encode_write(link_.bus_id(device), address, {data, size}, link_.tx());
  return unicast(device, length, 0, tries);
}

void DynamixelBus::read_pending_hardware_status() {
  if (!link_.fault_pending()) return;
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    if (!link_.take_new_fault(i)) continue;
    DeviceStatus& st = link_.book()[i];
    const std::size_t length =
        dxl::encode_read(link_.bus_id(i), dxl::xreg::hardware_error_status, 1, link_.tx());
    // The diagnosis must not overwrite the verdict of the cycle.
    const DeviceHealth health = st.health;
    if (unicast(i, length, 1, 1, true) == Answer::ok) {
      st.hardware_error_status = static_cast<std::uint8_t>(link_.value(0));
    }
    st.health = health;
  }
}

std::string DynamixelBus::failure(std::size_t device, Answer answer) const {
  const DeviceStatus& st = link_.book()[device];
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
  latency_warning_ = latency_timer_warning(link_.transport().port(), sysfs_root_);
  if (!latency_warning_.empty()) {
    std::fprintf(stderr, "warning: bus %s: %s\n", config_.name.c_str(), latency_warning_.c_str());
  }
  const std::size_t n = link_.book().size();
  link_.reset();
  positions_.forget_found();

  link_.ping_all(kTries, dxl::encode_ping, [&](std::size_t i) {
    // Model number (2 bytes), firmware version.
    model_[i] = static_cast<std::uint16_t>(link_.value(0) & 0xFFFF);
    firmware_[i] = static_cast<std::uint8_t>((link_.value(0) >> 16) & 0xFF);
  });

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
  // Before the positions: entering position mode restarts a servo's count.
  set_operating_modes();

  std::string unread;
  for (std::size_t i = 0; i < n; ++i) {
    const auto id = link_.bus_id(i);
    const std::size_t length = dxl::encode_read(id, dxl::xreg::present_position, 4, link_.tx());
    const Answer a = unicast(i, length, 4);
    if (a == Answer::ok) {
      positions_.found(i, static_cast<std::int32_t>(link_.value(0)));
    } else {
      unread += (unread.empty() ? "" : "; ") + describe(i) + ": " + failure(i, a);
    }
  }
  if (!unread.empty()) throw DeviceError(prefix() + "cannot read present position of " + unread);
  clear_bus_watchdogs();
  outside_warning_ = positions_.start(link_.book(), "position limits");
  for (std::size_t i = 0; i < n; ++i) write_position_limits(i);
  for (std::size_t i = 0; i < n; ++i) {
    current_unit_[i] = dxl::current_unit_a(model_[i]);
    if (health_ != dxl::HealthRead::off) map_health_registers(i);
  }
  health_next_ = 0;
  choose_fast_read();
  read_pending_hardware_status();
  positions_.ready();
}

void DynamixelBus::map_health_registers(std::size_t device) {
  // Indirect Address n is RAM: written every configure (a reboot clears it).
  std::uint8_t data[2 * kPackedLength];
  for (std::size_t k = 0; k < kPackedLength; ++k) dxl::put_u16(data + 2 * k, kHealthMap[k]);
  const std::size_t length = dxl::encode_write(link_.bus_id(device), dxl::xreg::indirect_address_1,
                                               {data, sizeof data}, link_.tx());
  const Answer r = unicast(device, length, 0);
  if (r != Answer::ok) {
    throw DeviceError(prefix() + "cannot map the health registers (Indirect Address 1.." +
                      std::to_string(kPackedLength) + ") of " + describe(device) + ": " +
                      failure(device, r));
  }
}

std::uint16_t DynamixelBus::cycle_address() const {
  return health_ == dxl::HealthRead::packed ? dxl::xreg::indirect_data_1
                                            : dxl::xreg::present_position;
}

std::uint16_t DynamixelBus::cycle_length() const {
  return health_ == dxl::HealthRead::packed ? kPackedLength : 4;
}

void DynamixelBus::take_health(std::size_t device, std::span<const std::uint8_t> data) {
  if (data.size() < kHealthLength) return;
  HealthReading& h = link_.book()[device].reading;
  const auto raw_current = static_cast<std::int16_t>(dxl::get_u16(&data[0]));
  h.current_a = current_unit_[device] > 0.0
                    ? std::abs(static_cast<double>(raw_current)) * current_unit_[device]
                    : HealthReading::kNone;
  h.voltage_v = 0.1 * static_cast<double>(dxl::get_u16(&data[2]));
  h.temperature_c = static_cast<double>(data[4]);
  h.error_bits = data[5];
  h.has_error_bits = true;
  h.read_ns = steady_ns();
  ++h.reads;
}

void DynamixelBus::read_health_round_robin() {
  const std::size_t n = link_.book().size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = (health_next_ + k) % n;
    if (link_.book()[i].faulted) continue;
    health_next_ = (i + 1) % n;
    DeviceStatus& st = link_.book()[i];
    const std::size_t length = dxl::encode_read(
        link_.bus_id(i), dxl::xreg::indirect_data_1 + kHealthOffset, kHealthLength, link_.tx());
    // A lost health read is counted, but the cycle's verdict is the position's.
    const DeviceHealth health = st.health;
    if (unicast(i, length, kHealthLength, 1) == Answer::ok) take_health(i, link_.data(0));
    st.health = health;
    return;
  }
}

void DynamixelBus::clear_bus_watchdogs() {
  // A run that died with the Bus Watchdog set leaves it counting, or fired
  // (goals refused until it reads 0): either way it starts from 0 here.
  watchdog_warning_.clear();
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    const auto id = link_.bus_id(i);
    Answer r = unicast(i, dxl::encode_read(id, dxl::xreg::bus_watchdog, 1, link_.tx()), 1);
    if (r != Answer::ok || link_.value(0) == 0) continue;  // older firmware: no such item
    const bool fired = link_.value(0) == dxl::kBusWatchdogFired;
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
  const std::size_t n = link_.book().size();
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
  const auto book = link_.book().devices();
  const std::vector<DeviceStatus> before(book.begin(), book.end());
  for (std::size_t i = 0; i < n; ++i) link_.ask(i, i);
  const std::size_t length =
      dxl::encode_fast_sync_read(cycle_address(), cycle_length(), link_.ids().first(n), link_.tx());
  if (length > 0) {
    transact_fast(length, n, cycle_length());
    fast_ = true;
    for (std::size_t s = 0; s < n; ++s) fast_ = fast_ && link_.answer(s) == Answer::ok;
  }
  std::copy(before.begin(), before.end(), book.begin());
}

void DynamixelBus::write_position_limits(std::size_t device) {
  const ActuatorBinding& b = config_.actuators[device];
  // Extended position mode does not use the position limits.
  if (!b.has_limits() || dxl::device_options(b).multi_turn) return;
  // Inside the range X-series position mode accepts (0..4095); a joint
  // resting outside its limits would otherwise get a Data Limit Error.
  const auto span = positions_.limit_ticks(device, kXMaxTicks);
  const auto lo = static_cast<std::uint32_t>(span.lo);
  const auto hi = static_cast<std::uint32_t>(span.hi);
  const auto id = link_.bus_id(device);
  const auto fail = [&](Answer answer, const std::string& what) {
    throw DeviceError(prefix() + "cannot " + what + " of " + describe(device) + ": " +
                      failure(device, answer));
  };
  std::uint32_t now_lo = 0, now_hi = 0;
  Answer r = unicast(device, dxl::encode_read(id, dxl::xreg::max_position_limit, 4, link_.tx()), 4);
  if (r != Answer::ok) fail(r, "read Max Position Limit");
  now_hi = link_.value(0);
  r = unicast(device, dxl::encode_read(id, dxl::xreg::min_position_limit, 4, link_.tx()), 4);
  if (r != Answer::ok) fail(r, "read Min Position Limit");
  now_lo = link_.value(0);
  if (now_lo == lo && now_hi == hi) return;  // EEPROM: written only when it differs
  // EEPROM items are locked while torque is on.
  r = unicast(device, dxl::encode_read(id, dxl::xreg::torque_enable, 1, link_.tx()), 1);
  if (r != Answer::ok) fail(r, "read Torque Enable");
  if (link_.value(0) != 0) {
    r = write_register(device, dxl::xreg::torque_enable, 0, 1, kTries);
    if (r != Answer::ok) fail(r, "turn torque off to write the position limits");
  }
  r = write_register(device, dxl::xreg::max_position_limit, hi, 4, kTries);
  if (r != Answer::ok) fail(r, "write Max Position Limit " + std::to_string(hi));
  r = write_register(device, dxl::xreg::min_position_limit, lo, 4, kTries);
  if (r != Answer::ok) fail(r, "write Min Position Limit " + std::to_string(lo));
}

void DynamixelBus::activate() {
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    if (link_.book()[i].faulted) continue;
    // Goal = where the servo is, so torque on cannot jump to a stale goal.
    const std::int32_t ticks = positions_.present(i);
    const auto check = [&](Answer a, const char* action) {
      if (a == Answer::ok && (link_.book()[i].last_error_byte & dxl::kAlertBit) == 0) return;
      // A servo in hardware error shutdown would stay limp: refuse to start.
      if (a == Answer::ok) read_pending_hardware_status();
      // The Alert stays until the servo restarts: say how, once its cause is gone.
      const std::string reboot =
          a == Answer::ok ? "; once its cause is gone, a power cycle or `animrt servo " +
                                config_.port + " --protocol dynamixel2 --id " +
                                std::to_string(config_.actuators[i].device_id) + " --baud " +
                                std::to_string(config_.baud) + " reboot` clears it"
                          : std::string();
      const std::string message =
          prefix() + "cannot " + action + " of " + describe(i) + ": " + failure(i, a) + reboot;
      deactivate();
      throw DeviceError(message);
    };
    check(write_register(i, dxl::xreg::goal_position, static_cast<std::uint32_t>(ticks), 4, kTries),
          "write goal position");
    positions_.found(i, ticks);
    check(write_register(i, dxl::xreg::torque_enable, 1, 1, kTries), "enable torque");
  }
}

void DynamixelBus::arm_device_guard() {
  if (watchdog_units_ == 0) return;
  // After torque on: a servo watches the line only while torque is on.
  broadcast_bus_watchdog();
  std::string unset;
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    if (link_.book()[i].faulted) continue;
    const auto id = link_.bus_id(i);
    const Answer r = unicast(i, dxl::encode_read(id, dxl::xreg::bus_watchdog, 1, link_.tx()), 1);
    if (r != Answer::ok || link_.value(0) != watchdog_units_) {
      unset += (unset.empty() ? "" : ", ") + describe(i) + ": " +
               (r == Answer::ok ? "reads " + std::to_string(link_.value(0)) : failure(i, r));
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
  last_answered_ = link_.last_sent();
  armed_ = true;
}

void DynamixelBus::broadcast_bus_watchdog() {
  // 0 first: a guard that fired (255) takes a new time only from 0.
  for (const std::uint8_t value : {std::uint8_t{0}, watchdog_units_}) {
    const std::size_t length =
        dxl::encode_write(dxl::kBroadcastId, dxl::xreg::bus_watchdog, {&value, 1}, link_.tx());
    if (length > 0) link_.send(length);
  }
}

void DynamixelBus::deactivate() {
  armed_ = false;
  const decltype(link_)::Stopping stopping(link_);
  try {
    for (std::size_t i = 0; i < link_.book().size(); ++i) {
      // Before torque off, so a clean stop leaves no guard armed (and clears
      // one that fired). Not for a device the cycle left out: a silent one
      // would only delay its torque-off; the next configure clears it.
      if (watchdog_units_ > 0 && !link_.book()[i].faulted) {
        write_register(i, dxl::xreg::bus_watchdog, 0, 1, kTries);
      }
      write_register(i, dxl::xreg::torque_enable, 0, 1, kTries);
      restore_operating_mode(i);
    }
  } catch (...) {
    // The line is gone: nothing more can be sent, and deactivate never throws.
  }
}

// ---- cycle ----------------------------------------------------------------

void DynamixelBus::switch_off(std::size_t device) {
  mark_faulted(device);
  off_pending_[device] = 1;
}

void DynamixelBus::read(std::span<double> positions) {
  positions_.hand_out_found(positions);
  rearm_after_silence();
  for (std::size_t i = 0; i < off_pending_.size(); ++i) {
    if (!off_pending_[i]) continue;
    off_pending_[i] = 0;
    // One try: a servo that does not hear it is switched off by deactivate().
    const DeviceHealth health = link_.book()[i].health;
    write_register(i, dxl::xreg::torque_enable, 0, 1, 1);
    link_.book()[i].health = health;
  }
  const std::size_t count = link_.ask_all_healthy();
  if (count > 0) {
    const std::uint16_t address = cycle_address();
    const std::uint16_t data_length = cycle_length();
    const bool packed = health_ == dxl::HealthRead::packed;
    const std::size_t length =
        fast_
            ? dxl::encode_fast_sync_read(address, data_length, link_.ids().first(count), link_.tx())
            : dxl::encode_sync_read(address, data_length, link_.ids().first(count), link_.tx());
    if (length > 0) {
      if (fast_) {
        transact_fast(length, count, data_length);
      } else {
        link_.transact(length, count, data_length);
      }
      for (std::size_t s = 0; s < count; ++s) {
        if (link_.answer(s) != Answer::ok) continue;
        last_answered_ = steady_clock::now();
        positions_.measured(link_.asked(s), static_cast<std::int32_t>(link_.value(s)), positions);
        if (packed) take_health(link_.asked(s), link_.data(s).subspan(kHealthOffset));
      }
    }
    if (health_ == dxl::HealthRead::round_robin) read_health_round_robin();
  }
  // Only after an alert appeared: one extra transaction in that failure case.
  read_pending_hardware_status();
}

void DynamixelBus::write(std::span<const double> positions) {
  rearm_after_silence();
  std::size_t count = 0;
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    if (link_.book()[i].faulted) continue;
    const std::int32_t goal =
        i < positions.size() ? positions_.take_goal(i, positions[i]) : positions_.goal(i);
    link_.ids()[count] = link_.bus_id(i);
    dxl::put_u32(sync_data_.data() + 4 * count, static_cast<std::uint32_t>(goal));
    ++count;
  }
  if (count == 0) return;
  const std::size_t length =
      dxl::encode_sync_write(dxl::xreg::goal_position, 4, link_.ids().first(count),
                             {sync_data_.data(), 4 * count}, link_.tx());
  if (length > 0) {
    link_.send(length);
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
  if (now - link_.last_sent() <= half && now - last_answered_ <= half) return;
  // So the guard may have fired: the servos stopped and refuse goals.
  // Broadcast, so no answers to wait for.
  broadcast_bus_watchdog();
  ++watchdog_rearms_;
}

}  // namespace animrt
