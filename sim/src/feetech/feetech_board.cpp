#include "animrt/sim/feetech/feetech_board.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "animrt/core/error.hpp"
#include "animrt/sim/dynamixel_servo.hpp"  // initial_position_rad

namespace animrt::sim {
namespace {

namespace reg = ft::reg;

// A hand overpowers an STS whose Torque Limit is at most a quarter of its
// maximum torque, and lets go of a joint it holds once the servo's goal is
// this close to where the hand holds it (as the Dynamixel simulation).
constexpr std::uint16_t kHandOverpowersLimit = ft::kStsFullTorque / 4;
constexpr double kHandLetsGoSteps = 4.0;

// STS3215 identity (memory table v3.6): firmware 3.6, servo version 9.3.
constexpr std::uint8_t kStsModel[2] = {9, 3};
constexpr std::uint8_t kScsModel[2] = {5, 4};
// Unload Condition default of the STS3215: temperature, current, overload.
constexpr std::uint8_t kDefaultUnload =
    ft::error_bit::temperature | ft::error_bit::current | ft::error_bit::overload;
// Voltage and temperature as in the Sync Read example of the protocol manual.
constexpr std::uint8_t kTemperatureC = 30;
constexpr std::uint8_t kVoltageDeciV = 121;

// Addresses a master may write (the rest is read-only).
bool writable(std::size_t address) {
  switch (address) {
    case reg::id:
    case reg::baud_rate:
    case reg::return_delay:
    case reg::status_return_level:
    case reg::min_angle_limit:
    case reg::min_angle_limit + 1:
    case reg::max_angle_limit:
    case reg::max_angle_limit + 1:
    case reg::max_temperature:
    case reg::unload_condition:
    case reg::position_offset:
    case reg::position_offset + 1:
    case reg::operating_mode:
    case reg::torque_enable:
    case reg::acceleration:
    case reg::goal_position:
    case reg::goal_position + 1:
    case reg::goal_time:
    case reg::goal_time + 1:
    case reg::goal_speed:
    case reg::goal_speed + 1:
    case reg::scs_lock:  // STS: Torque Limit's low byte
    case reg::sts_torque_limit + 1:
    case reg::sts_lock:
      return true;
    default:
      return false;
  }
}

// The health model at the board's own rest values (the manual's 12.1 V and
// 30 C) unless the robot file's sim.health sets them.
SimHealthSettings feetech_health(SimHealthSettings h) {
  const SimHealthSettings defaults;
  if (h.ambient_c == defaults.ambient_c) h.ambient_c = kTemperatureC;
  if (h.supply_v == defaults.supply_v) h.supply_v = kVoltageDeciV / 10.0;
  return h;
}

}  // namespace

bool feetech_may_answer(const ft::Packet& packet) {
  if (packet.id != ft::kBroadcastId) return true;
  return packet.code == ft::inst::ping || packet.code == ft::inst::sync_read;
}

// ---- one servo ---------------------------------------------------------------

FeetechServo::FeetechServo(const ActuatorBinding& binding, ft::Series series,
                           const SimBusSettings& settings, int baud, Nanos now)
    : binding_(binding),
      series_(series),
      tau_s_(std::max(0.0, settings.time_constant_s)),
      vmax_steps_s_(std::max(0.0, settings.max_speed_rad_s * binding.ticks_per_rad)),
      eeprom_(series == ft::Series::sts ? kFeetechSts : kFeetechScs),
      motor_time_(now),
      health_(feetech_health(settings.health), binding.device_id, now) {
  const bool sts = series_ == ft::Series::sts;
  table_[reg::firmware_major] = 3;
  std::memcpy(&table_[reg::model], sts ? kStsModel : kScsModel, 2);
  table_[reg::id] = static_cast<std::uint8_t>(binding.device_id);
  table_[reg::baud_rate] = baud_register(eeprom_.family(), baud);
  table_[reg::return_delay] =
      static_cast<std::uint8_t>(std::clamp(settings.return_delay_us / 2, 0, 254));
  table_[reg::status_return_level] = 1;
  ft::put_u16(series_, &table_[reg::min_angle_limit], 0);
  ft::put_u16(series_, &table_[reg::max_angle_limit],
              static_cast<std::uint16_t>(sts ? ft::kStsMaxPosition : ft::kScsMaxPosition));
  table_[reg::max_temperature] = 70;
  table_[reg::unload_condition] = kDefaultUnload;
  table_[reg::present_voltage] = kVoltageDeciV;
  table_[reg::present_temperature] = kTemperatureC;
  if (sts) ft::put_u16(series_, &table_[reg::sts_torque_limit], ft::kStsFullTorque);
  const double start = binding.to_ticks(initial_position_rad(binding));
  motor_.position = std::clamp(start, static_cast<double>(position_value(reg::min_angle_limit)),
                               static_cast<double>(position_value(reg::max_angle_limit)));
  // Hold still when torque comes on: the goal starts at the present position.
  store_position(reg::goal_position, motor_.position);
  publish();
  eeprom_.build(table_);
}

std::uint16_t FeetechServo::u16(std::uint8_t address) const {
  return ft::get_u16(series_, &table_[address]);
}

std::int32_t FeetechServo::position_value(std::uint8_t address) const {
  const std::uint16_t raw = u16(address);
  return series_ == ft::Series::sts ? ft::decode_signed(raw, ft::kStsSignBit) : raw;
}

void FeetechServo::store_position(std::uint8_t address, double steps) {
  const auto v = static_cast<std::int32_t>(std::lround(steps));
  const std::uint16_t raw = series_ == ft::Series::sts
                                ? ft::encode_signed(v, ft::kStsSignBit)
                                : static_cast<std::uint16_t>(std::clamp(v, 0, 0xFFFF));
  ft::put_u16(series_, &table_[address], raw);
}

std::int32_t FeetechServo::goal_position() const {
  const std::int32_t lo = position_value(reg::min_angle_limit);
  const std::int32_t hi = position_value(reg::max_angle_limit);
  const std::int32_t goal = position_value(reg::goal_position);
  // Both limits 0: multi-turn (STS step mode), no clamp.
  if (lo == 0 && hi == 0) return goal;
  return std::clamp(goal, lo, std::max(lo, hi));
}

FeetechServo::Motor FeetechServo::motor_at(Nanos now) const {
  Motor m = motor_;
  // Blocked, or a hand holds it against a weak torque: held where it is.
  if (!torque_on() || vmax_steps_s_ <= 0 || health_.blocked() || held_by_hand_) {
    m.velocity = 0;
    return m;
  }
  if (now <= motor_time_) return m;
  return m.after(to_seconds(now - motor_time_), goal_position(), vmax_steps_s_, tau_s_);
}

void FeetechServo::advance(Nanos now) {
  if (now <= motor_time_) return;
  motor_ = motor_at(now);
  motor_time_ = now;
  health_.advance(now, motor_.velocity / binding_.ticks_per_rad, torque_on());
  publish();
}

void FeetechServo::publish() {
  store_position(reg::present_position, motor_.position);
  const auto speed = static_cast<std::int32_t>(std::lround(motor_.velocity));
  // Speeds carry their direction in bit 15 on both series.
  ft::put_u16(series_, &table_[reg::present_speed], ft::encode_signed(speed, ft::kStsSignBit));
  table_[reg::moving] = std::abs(motor_.velocity) > 1.0 ? 1 : 0;
  // What the servo reads about itself: load (0.1 % of the stall current,
  // direction in bit 10), supply, temperature, and on STS the current
  // (6.5 mA units); its status bits from them, as its firmware sets them
  // (voltage, temperature, overload share the layout the model uses).
  const double amps = health_.current_a();
  // Load: the current beyond holding, against the stall current (0 at rest).
  const SimHealthSettings& model = health_.settings();
  const double span = std::max(1e-3, model.stall_current_a - model.idle_current_a);
  const auto load = static_cast<std::int32_t>(
      std::lround(std::clamp(1000.0 * (amps - model.idle_current_a) / span, 0.0, 1000.0)));
  ft::put_u16(series_, &table_[reg::present_load],
              ft::encode_signed(motor_.velocity < 0 ? -load : load, ft::kScsSignBit));
  table_[reg::present_voltage] =
      static_cast<std::uint8_t>(std::clamp(std::lround(10.0 * health_.voltage_v()), 0L, 255L));
  table_[reg::present_temperature] =
      static_cast<std::uint8_t>(std::clamp(std::lround(health_.temperature_c()), 0L, 255L));
  if (series_ == ft::Series::sts) {
    const auto units = static_cast<std::int32_t>(std::lround(amps / 0.0065));
    ft::put_u16(series_, &table_[69], ft::encode_signed(units, ft::kStsSignBit));
  }
  const std::uint8_t bits = static_cast<std::uint8_t>(
      injected_ | health_.error_bits(table_[reg::max_temperature], 0.0, 1e9));
  table_[reg::servo_status] = bits;
  if ((bits & table_[reg::unload_condition]) != 0 && torque_on()) {
    table_[reg::torque_enable] = 0;
    motor_.velocity = 0;
  }
}

bool FeetechServo::read(std::uint8_t address, std::uint8_t length,
                        std::span<std::uint8_t> out) const {
  if (static_cast<std::size_t>(address) + length > table_.size() || out.size() < length) {
    return false;
  }
  std::memcpy(out.data(), &table_[address], length);
  return true;
}

void FeetechServo::write(std::uint8_t address, std::span<const std::uint8_t> data) {
  const bool torque_was_on = torque_on();
  const bool keep =
      eeprom_write(eeprom_.family(), table_, address, data.size()) == EepromWrite::kept;
  bool goal_written = false;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const std::size_t a = address + i;
    if (a >= table_.size() || !writable(a)) continue;
    if (a == reg::torque_enable) {
      // A latched fault in Unload Condition keeps torque off.
      const bool unloaded = (table_[reg::servo_status] & table_[reg::unload_condition]) != 0;
      table_[a] = unloaded ? 0 : static_cast<std::uint8_t>(data[i] != 0 ? 1 : 0);
      continue;
    }
    table_[a] = data[i];
    if (a == reg::goal_position + 1u) goal_written = true;
  }
  if (keep) eeprom_.keep(table_);
  if (goal_written) {
    ++goals_received_;
    last_goal_ = position_value(reg::goal_position);
  }
  if (torque_was_on != torque_on()) {
    motor_.velocity = 0;
    publish();
  }
  let_go_of_hand();
}

void FeetechServo::reg_write(std::uint8_t address, std::span<const std::uint8_t> data) {
  const std::size_t n = std::min(data.size(), pending_.size());
  std::memcpy(pending_.data(), data.data(), n);
  pending_address_ = address;
  pending_length_ = static_cast<std::uint8_t>(n);
  table_[reg::registered] = 1;
}

void FeetechServo::action() {
  if (table_[reg::registered] == 0) return;
  table_[reg::registered] = 0;
  write(pending_address_, {pending_.data(), pending_length_});
}

void FeetechServo::set_fault(std::uint8_t bits, Nanos now) {
  advance(now);
  injected_ = bits;
  publish();
}

void FeetechServo::power_up(Nanos now) {
  // EEPROM as kept; torque off, nothing registered, the lock open, the goal
  // where the shaft is.
  advance(now);
  eeprom_.load(table_);
  table_[reg::torque_enable] = 0;
  table_[reg::registered] = 0;
  table_[static_cast<std::size_t>(eeprom_.family().lock_address)] = 0;
  if (series_ == ft::Series::sts) {
    ft::put_u16(series_, &table_[reg::sts_torque_limit], ft::kStsFullTorque);
  }
  held_by_hand_ = false;
  motor_.velocity = 0;
  store_position(reg::goal_position, motor_.position);
  publish();
}

void FeetechServo::set_plugged(bool plugged, Nanos now) {
  if (plugged && !plugged_) power_up(now);
  plugged_ = plugged;
}

bool FeetechServo::restore_eeprom(std::span<const std::uint8_t> kept, Nanos now) {
  if (!eeprom_.restore(kept, table_)) return false;
  power_up(now);
  return true;
}

void FeetechServo::factory_reset(Nanos now) {
  eeprom_.factory_reset(table_, false, false);
  power_up(now);
}

bool FeetechServo::yields_to_hand() const {
  if (!torque_on()) return true;
  return series_ == ft::Series::sts && u16(reg::sts_torque_limit) <= kHandOverpowersLimit;
}

void FeetechServo::let_go_of_hand() {
  if (!held_by_hand_) return;
  const bool pulls_away = std::abs(goal_position() - motor_.position) > kHandLetsGoSteps;
  if (!torque_on() || !yields_to_hand() || !pulls_away) held_by_hand_ = false;
}

bool FeetechServo::hand_move(std::int32_t steps, Nanos now) {
  advance(now);
  if (!yields_to_hand()) return false;
  motor_.position = steps;
  motor_.velocity = 0;
  // Against a weak torque the hand holds the joint until the servo's goal
  // comes to it; a limp joint simply stays.
  held_by_hand_ = torque_on();
  let_go_of_hand();
  publish();
  return true;
}

int FeetechServo::baud() const { return baud_of(eeprom_.family(), table_[reg::baud_rate]); }

std::int32_t FeetechServo::present_steps(Nanos now) const {
  return static_cast<std::int32_t>(std::lround(motor_at(std::max(now, motor_time_)).position));
}

double FeetechServo::position_rad(Nanos now) const {
  const Motor m = motor_at(std::max(now, motor_time_));
  return binding_.direction * (m.position - binding_.zero_ticks) / binding_.ticks_per_rad;
}

// ---- the board ----------------------------------------------------------------

FeetechBoard::FeetechBoard(const BusConfig& config, ft::Series series, Nanos now)
    : series_(series) {
  servos_.reserve(config.actuators.size());
  for (const ActuatorBinding& b : config.actuators) {
    if (b.device_id < 0 || b.device_id > ft::kMaxDeviceId) {
      throw InputError(config.where, "id",
                       "Feetech id " + std::to_string(b.device_id) + " of joint '" +
                           elide(b.joint) + "' is outside 0.." + std::to_string(ft::kMaxDeviceId));
    }
    if (find_configured(b.device_id) != nullptr) {
      throw InputError(config.where, "id",
                       "Feetech id " + std::to_string(b.device_id) + " is used twice on bus '" +
                           elide(config.name) + "'");
    }
    servos_.emplace_back(b, series, config.sim, config.baud, now);
  }
}

FeetechServo* FeetechBoard::find_configured(int device_id) {
  for (FeetechServo& s : servos_) {
    if (s.device_id() == device_id) return &s;
  }
  return nullptr;
}

const FeetechServo* FeetechBoard::find_configured(int device_id) const {
  for (const FeetechServo& s : servos_) {
    if (s.device_id() == device_id) return &s;
  }
  return nullptr;
}

template <class Act>
void FeetechBoard::for_id(std::uint8_t id, FeetechAnswers& out, Act&& act) {
  const std::size_t first = out.list.size();
  for (FeetechServo& s : servos_) {
    if (s.id() == id && s.responding()) act(s);
  }
  collide(out, first);
}

void FeetechBoard::answer(const FeetechServo& servo, std::span<const std::uint8_t> data,
                          FeetechAnswers& out) const {
  const std::size_t offset = out.bytes.size();
  out.bytes.resize(offset + ft::kMaxPacket);
  const std::size_t n = ft::encode_status(servo.id(), servo.error_byte(), data,
                                          {out.bytes.data() + offset, ft::kMaxPacket});
  out.bytes.resize(offset + n);
  if (n > 0) out.list.push_back({offset, n, servo.return_delay_us()});
}

void FeetechBoard::handle(const ft::Packet& packet, Nanos now, FeetechAnswers& out, int line_baud) {
  for (FeetechServo& s : servos_) {
    s.advance(now);
    s.set_hearing(line_baud == 0 || s.baud() == line_baud);
  }
  const std::span<const std::uint8_t> p = packet.params;
  const bool broadcast = packet.id == ft::kBroadcastId;
  auto each_target = [&](auto&& act) {
    if (broadcast) {
      for (FeetechServo& s : servos_) {
        if (s.responding()) act(s);
      }
    } else {
      for_id(packet.id, out, act);
    }
  };
  // Write, Reg Write and Action answer per Status Return Level (the level the
  // packet arrived under), never to a broadcast.
  auto acknowledge = [&](const FeetechServo& s, std::uint8_t level) {
    if (!broadcast && level >= 1) answer(s, {}, out);
  };
  std::array<std::uint8_t, 256> data{};
  switch (packet.code) {
    case ft::inst::ping:
      if (broadcast) {
        // Every servo answers; those sharing an ID at once.
        std::array<bool, 256> done{};
        for (const FeetechServo& s : servos_) {
          if (!s.responding() || done[s.id()]) continue;
          done[s.id()] = true;
          for_id(s.id(), out, [&](FeetechServo& t) { answer(t, {}, out); });
        }
      } else {
        each_target([&](FeetechServo& s) { answer(s, {}, out); });
      }
      break;
    case ft::inst::read:
      if (broadcast || p.size() != 2) break;
      for_id(packet.id, out, [&](FeetechServo& s) {
        if (s.read(p[0], p[1], data)) answer(s, {data.data(), p[1]}, out);
      });
      break;
    case ft::inst::write:
    case ft::inst::reg_write:
      if (p.size() < 2) break;
      each_target([&](FeetechServo& s) {
        const std::uint8_t level = s.status_return_level();
        if (packet.code == ft::inst::write) {
          s.write(p[0], p.subspan(1));
        } else {
          s.reg_write(p[0], p.subspan(1));
        }
        acknowledge(s, level);
      });
      break;
    case ft::inst::action:
      each_target([&](FeetechServo& s) {
        const std::uint8_t level = s.status_return_level();
        s.action();
        acknowledge(s, level);
      });
      break;
    case ft::inst::sync_read:
      // Only STS servos know Sync Read; each listed servo answers in turn.
      if (series_ != ft::Series::sts || !broadcast || p.size() < 3) break;
      for (std::uint8_t id : p.subspan(2)) {
        for_id(id, out, [&](FeetechServo& s) {
          if (s.read(p[0], p[1], data)) answer(s, {data.data(), p[1]}, out);
        });
      }
      break;
    case ft::inst::sync_write: {
      if (!broadcast || p.size() < 2) break;
      const std::size_t length = p[1];
      const std::span<const std::uint8_t> blocks = p.subspan(2);
      if (length == 0 || blocks.size() % (length + 1) != 0) break;  // malformed: ignored
      for (std::size_t i = 0; i < blocks.size(); i += length + 1) {
        for_id(blocks[i], out,
               [&](FeetechServo& s) { s.write(p[0], blocks.subspan(i + 1, length)); });
      }
      break;
    }
    default:
      break;  // Reset and unknown instructions: not modelled, no answer
  }
}

}  // namespace animrt::sim
