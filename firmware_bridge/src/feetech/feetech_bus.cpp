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

using servo::Answer;
constexpr std::size_t kAnyLength = servo::kAnyLength;

std::string error_text(std::uint8_t bits) {
  static constexpr servo::FaultBit kBits[] = {
      {ft::error_bit::voltage, "voltage"},
      {ft::error_bit::sensor, "sensor"},
      {ft::error_bit::temperature, "temperature"},
      {ft::error_bit::current, "current"},
      {ft::error_bit::angle, "angle"},
      {ft::error_bit::overload, "overload"},
  };
  return servo::fault_text("servo status", bits, kBits);
}

}  // namespace

FeetechBus::FeetechBus(BusConfig config, ft::Series series,
                       std::unique_ptr<ByteTransport> transport)
    : config_(std::move(config)),
      series_(series),
      link_(config_, std::move(transport), ft::LinkCodec{series}),
      // STS positions are sign-magnitude (bit 15), SCS positions unsigned.
      min_ticks_(series == ft::Series::sts ? -((1 << ft::kStsSignBit) - 1) : 0),
      max_ticks_(series == ft::Series::sts ? (1 << ft::kStsSignBit) - 1 : ft::kScsMaxPosition) {
  servo::check_bindings(config_, ft::kMaxDeviceId, kMaxDevices);
  const std::size_t n = config_.actuators.size();
  sync_data_.resize(2 * n);
  health_ = ft::bus_options(config_).health;
  positions_.init(config_, min_ticks_, max_ticks_);
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

Answer FeetechBus::write_byte(std::size_t device, std::uint8_t address, std::uint8_t value) {
  const std::uint8_t id = link_.bus_id(device);
  return unicast(device, ft::encode_write(id, address, {&value, 1}, link_.tx()), 0);
}

Answer FeetechBus::write_goal(std::size_t device, std::int32_t ticks) {
  std::uint8_t data[2];
  ft::put_u16(series_, data, from_position(ticks));
  const std::uint8_t id = link_.bus_id(device);
  return unicast(device, ft::encode_write(id, ft::reg::goal_position, data, link_.tx()), 0);
}

std::string FeetechBus::failure(std::size_t device, Answer answer) const {
  switch (answer) {
    case Answer::timeout:
      return "no answer";
    case Answer::garbled:
      return "garbled answer";
    case Answer::rejected:  // nothing refuses, but an answer may be short
      return "answer with the wrong data length";
    case Answer::ok:
    case Answer::pending:
      break;
  }
  return "servo reports a fault (" + error_text(link_.book()[device].last_error_byte) + ")";
}

// ---- lifecycle --------------------------------------------------------------

void FeetechBus::configure() {
  const std::size_t n = link_.book().size();
  link_.reset();
  positions_.forget_found();

  link_.ping_all(kTries, ft::encode_ping, [](std::size_t) {});
  std::string unread;
  for (std::size_t i = 0; i < n; ++i) {
    const auto id = link_.bus_id(i);
    const Answer a = unicast(i, ft::encode_read(id, ft::reg::present_position, 2, link_.tx()), 2);
    if (a == Answer::ok) {
      positions_.found(i, to_position(static_cast<std::uint16_t>(link_.value(0))));
    } else {
      unread += (unread.empty() ? "" : "; ") + describe(i) + ": " + failure(i, a);
    }
  }
  if (!unread.empty()) throw DeviceError(prefix() + "cannot read present position of " + unread);
  outside_warning_ = positions_.start(link_.book(), "angle limits");
  for (std::size_t i = 0; i < n; ++i) write_angle_limits(i);
  positions_.ready();
}

void FeetechBus::write_angle_limits(std::size_t device) {
  const ActuatorBinding& b = config_.actuators[device];
  if (!b.has_limits()) return;
  // Inside the position-mode range of the series.
  const std::int32_t top = series_ == ft::Series::sts ? ft::kStsMaxPosition : ft::kScsMaxPosition;
  const auto span = positions_.limit_ticks(device, top);
  const auto lo = static_cast<std::uint16_t>(span.lo);
  const auto hi = static_cast<std::uint16_t>(span.hi);
  const auto id = link_.bus_id(device);
  const auto fail = [&](Answer answer, const std::string& what) {
    throw DeviceError(prefix() + "cannot " + what + " of " + describe(device) + ": " +
                      failure(device, answer));
  };
  Answer r = unicast(device, ft::encode_read(id, ft::reg::min_angle_limit, 2, link_.tx()), 2);
  if (r != Answer::ok) fail(r, "read Min Angle Limit");
  const std::uint16_t now_lo = link_.value(0);
  r = unicast(device, ft::encode_read(id, ft::reg::max_angle_limit, 2, link_.tx()), 2);
  if (r != Answer::ok) fail(r, "read Max Angle Limit");
  if (now_lo == lo && link_.value(0) == hi) return;  // EEPROM: written only when it differs
  // EEPROM writes persist only while the lock flag is 0; lock it again after.
  const std::uint8_t lock = series_ == ft::Series::sts ? ft::reg::sts_lock : ft::reg::scs_lock;
  r = write_byte(device, lock, 0);
  if (r != Answer::ok) fail(r, "unlock the EEPROM");
  std::uint8_t data[4];
  ft::put_u16(series_, data, lo);
  ft::put_u16(series_, data + 2, hi);
  r = unicast(device, ft::encode_write(id, ft::reg::min_angle_limit, data, link_.tx()), 0);
  if (r != Answer::ok)
    fail(r, "write Min/Max Angle Limit " + std::to_string(lo) + ".." + std::to_string(hi));
  r = write_byte(device, lock, 1);
  if (r != Answer::ok) fail(r, "lock the EEPROM");
}

void FeetechBus::activate() {
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    if (link_.book()[i].faulted) continue;
    const auto check = [&](Answer a, const char* action) {
      if (a == Answer::ok && link_.book()[i].last_error_byte == 0) return;
      // A servo that reports a fault (overload, temperature...) stays limp
      // or cuts out: refuse to start.
      const std::string message =
          prefix() + "cannot " + action + " of " + describe(i) + ": " + failure(i, a);
      deactivate();
      throw DeviceError(message);
    };
    // Goal = where the servo is, so torque on cannot jump to a stale goal.
    check(write_goal(i, positions_.present(i)), "write goal position");
    positions_.found(i, positions_.present(i));
    check(write_byte(i, ft::reg::torque_enable, 1), "enable torque");
  }
}

void FeetechBus::deactivate() {
  const decltype(link_)::Stopping stopping(link_);
  try {
    for (std::size_t i = 0; i < link_.book().size(); ++i) {
      write_byte(i, ft::reg::torque_enable, 0);
      if (i < limit_before_.size() && limit_before_[i] != 0) {
        write_torque_limit(i, limit_before_[i]);
        limit_before_[i] = 0;
      }
    }
  } catch (...) {
    // The line is gone; deactivate never throws.
  }
}

// ---- cycle ----------------------------------------------------------------

namespace {
// Health read: Present Position (56) up to Present Current (69, 2 bytes) on
// STS, up to Present Temperature (63) on SCS.
constexpr std::size_t kStsHealthBytes = 15;
constexpr std::size_t kScsHealthBytes = 8;
constexpr double kStsCurrentUnitA = 0.0065;
}  // namespace

void FeetechBus::take_health(std::size_t device, std::span<const std::uint8_t> data) {
  if (data.size() < kScsHealthBytes) return;
  DeviceStatus& st = link_.book()[device];
  HealthReading& h = st.reading;
  h.voltage_v = 0.1 * data[ft::reg::present_voltage - ft::reg::present_position];
  h.temperature_c = data[ft::reg::present_temperature - ft::reg::present_position];
  if (data.size() >= kStsHealthBytes) {
    const std::uint16_t raw = ft::get_u16(series_, &data[69 - ft::reg::present_position]);
    h.current_a = std::abs(ft::decode_signed(raw, ft::kStsSignBit)) * kStsCurrentUnitA;
    h.error_bits = data[ft::reg::servo_status - ft::reg::present_position];
  } else {
    h.error_bits = st.last_error_byte;
  }
  h.has_error_bits = true;
  h.read_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                  std::chrono::steady_clock::now().time_since_epoch())
                  .count();
  ++h.reads;
}

void FeetechBus::read_positions(std::size_t count) {
  if (series_ == ft::Series::sts) {
    const std::size_t bytes = health_ ? kStsHealthBytes : 2;
    const std::size_t length =
        ft::encode_sync_read(ft::reg::present_position, static_cast<std::uint8_t>(bytes),
                             link_.ids().first(count), link_.tx());
    if (length > 0) link_.transact(length, count, bytes);
    return;
  }
  // SCS servos have no Sync Read: one Read each, in turn, each with its own
  // timeout. A transaction works on slot 0, so each servo is swapped there
  // while it is asked, and swapped back with its result.
  for (std::size_t s = 0; s < count; ++s) {
    link_.swap_slots(0, s);
    const std::size_t bytes = health_ ? kScsHealthBytes : 2;
    const std::size_t length = ft::encode_read(link_.ids()[0], ft::reg::present_position,
                                               static_cast<std::uint8_t>(bytes), link_.tx());
    link_.transact(length, 1, bytes);
    link_.swap_slots(0, s);
  }
}

void FeetechBus::read(std::span<double> positions) {
  positions_.hand_out_found(positions);
  const std::size_t count = link_.ask_all_healthy();
  if (count == 0) return;
  read_positions(count);
  for (std::size_t s = 0; s < count; ++s) {
    if (link_.answer(s) != Answer::ok) continue;
    positions_.measured(link_.asked(s), to_position(static_cast<std::uint16_t>(link_.value(s))),
                        positions);
    if (health_) take_health(link_.asked(s), link_.data(s));
  }
}

void FeetechBus::write(std::span<const double> positions) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    if (link_.book()[i].faulted) continue;
    const std::int32_t goal =
        i < positions.size() ? positions_.take_goal(i, positions[i]) : positions_.goal(i);
    link_.ids()[count] = link_.bus_id(i);
    ft::put_u16(series_, sync_data_.data() + 2 * count, from_position(goal));
    ++count;
  }
  if (count == 0) return;
  const std::size_t length =
      ft::encode_sync_write(ft::reg::goal_position, 2, link_.ids().first(count),
                            {sync_data_.data(), 2 * count}, link_.tx());
  if (length > 0) link_.send(length);
}

}  // namespace animrt
