#include "animrt/sim/dynamixel_servo.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>

#include "animrt/core/error.hpp"

namespace animrt::sim {
namespace {

using dxl::StatusError;
namespace xreg = dxl::xreg;

struct Item {
  std::uint16_t address;
  std::uint8_t size;
  bool writable;
  std::int64_t min = 0;  // a negative min makes the item signed
  std::int64_t max = 0;
};

// X430 control table (XM430-W350 / XH540-W270 e-manual pages; External Port
// items of the XH540 left out). Goal Position's range is the position limits
// (checked separately). Indirect Address / Data: find_item.
constexpr Item kItems[] = {
    {xreg::model_number, 2, false},
    {xreg_sim::model_information, 4, false},
    {xreg::firmware_version, 1, false},
    {xreg::id, 1, true, 0, 252},
    {xreg::baud_rate, 1, true, 0, 7},
    {xreg::return_delay_time, 1, true, 0, 254},
    {xreg_sim::drive_mode, 1, true, 0, 5},
    {xreg::operating_mode, 1, true, 3, 5},  // position, extended and current-based position
    {xreg_sim::secondary_id, 1, true, 0, 255},
    {xreg_sim::protocol_type, 1, true, 1, 2},
    {xreg_sim::homing_offset, 4, true, -1'044'479, 1'044'479},
    {xreg_sim::moving_threshold, 4, true, 0, 1023},
    {xreg_sim::temperature_limit, 1, true, 0, 100},
    {xreg_sim::max_voltage_limit, 2, true, 95, 160},
    {xreg_sim::min_voltage_limit, 2, true, 95, 160},
    {xreg_sim::pwm_limit, 2, true, 0, 885},
    {xreg_sim::current_limit, 2, true, 0, 1193},
    {xreg::velocity_limit, 4, true, 0, 1023},
    {xreg::max_position_limit, 4, true, 0, 4095},
    {xreg::min_position_limit, 4, true, 0, 4095},
    {xreg_sim::startup_configuration, 1, true, 0, 3},
    {xreg_sim::shutdown, 1, true, 0, 255},
    {xreg::torque_enable, 1, true, 0, 1},
    {xreg::led, 1, true, 0, 1},
    {xreg::status_return_level, 1, true, 0, 2},
    {xreg_sim::registered_instruction, 1, false},
    {xreg::hardware_error_status, 1, false},
    {xreg_sim::velocity_i_gain, 2, true, 0, 16383},
    {xreg_sim::velocity_p_gain, 2, true, 0, 16383},
    {xreg_sim::position_d_gain, 2, true, 0, 16383},
    {xreg_sim::position_i_gain, 2, true, 0, 16383},
    {xreg_sim::position_p_gain, 2, true, 0, 16383},
    {xreg_sim::feedforward_2nd_gain, 2, true, 0, 16383},
    {xreg_sim::feedforward_1st_gain, 2, true, 0, 16383},
    {xreg_sim::bus_watchdog, 1, true, 0, 127},
    {xreg_sim::goal_pwm, 2, true, -885, 885},
    {xreg_sim::goal_current, 2, true, -1193, 1193},
    {xreg_sim::goal_velocity, 4, true, -1023, 1023},
    {xreg_sim::profile_acceleration, 4, true, 0, 32767},
    {xreg_sim::profile_velocity, 4, true, 0, 32767},
    {xreg::goal_position, 4, true, INT32_MIN, INT32_MAX},
    {xreg_sim::realtime_tick, 2, false},
    {xreg::moving, 1, false},
    {xreg_sim::moving_status, 1, false},
    {xreg_sim::present_pwm, 2, false},
    {xreg_sim::present_current, 2, false},
    {xreg::present_velocity, 4, false},
    {xreg::present_position, 4, false},
    {xreg_sim::velocity_trajectory, 4, false},
    {xreg_sim::position_trajectory, 4, false},
    {xreg_sim::present_input_voltage, 2, false},
    {xreg::present_temperature, 1, false},
    {xreg_sim::backup_ready, 1, false},
};

constexpr std::uint8_t kPositionMode = 3;
constexpr std::uint8_t kExtendedPositionMode = 4;
constexpr std::uint8_t kCurrentBasedPositionMode = 5;
// A hand overpowers a servo whose Goal Current is at most this share of its
// Current Limit (about 0.7 Nm on an XM430-W210), and lets go of a joint it
// holds once the servo's goal is this close to where the hand holds it.
constexpr double kHandOverpowersShare = 0.25;
constexpr double kHandLetsGoTicks = 4.0;

// Extended and current-based position control: multi-turn, no position limits.
bool multi_turn(std::uint8_t mode) {
  return mode == kExtendedPositionMode || mode == kCurrentBasedPositionMode;
}
constexpr std::int32_t kExtendedPositionRange = 1'048'575;  // Goal Position, either way

// Indirect Address n: 2 bytes, 64..661. Indirect Data n: 1 byte.
constexpr std::int64_t kIndirectMin = xreg_sim::eeprom_end;
constexpr std::int64_t kIndirectMax = xreg::table_size - 1;

bool in_block(std::size_t address, std::size_t first, std::size_t item_size) {
  return address >= first && address < first + item_size * xreg::indirect_count;
}

bool find_item(std::size_t address, Item& out) {
  for (const std::uint16_t first : {xreg::indirect_address_1, xreg::indirect_address_29}) {
    if (in_block(address, first, 2)) {
      out = {static_cast<std::uint16_t>(address - (address - first) % 2), 2, true, kIndirectMin,
             kIndirectMax};
      return true;
    }
  }
  for (const std::uint16_t first : {xreg::indirect_data_1, xreg::indirect_data_29}) {
    if (in_block(address, first, 1)) {
      out = {static_cast<std::uint16_t>(address), 1, true, 0, 255};
      return true;
    }
  }
  for (const Item& item : kItems) {
    if (address >= item.address && address < item.address + item.size) {
      out = item;
      return true;
    }
  }
  return false;
}

std::uint32_t get_le(const std::uint8_t* p, std::size_t size) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < size; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}

// An item's value as the servo reads it: signed items are two's complement.
std::int64_t item_value(const Item& item, std::uint32_t raw) {
  if (item.min >= 0 || item.size >= 8) return raw;
  const unsigned bits = 8u * item.size;
  const std::uint32_t sign = 1u << (bits - 1);
  const std::int64_t v = raw & ((bits == 32) ? 0xFFFFFFFFu : ((1u << bits) - 1));
  return (v & sign) ? v - (std::int64_t{1} << bits) : v;
}

// Registers reset to these on power-on and Reboot (RAM) or kept (EEPROM).
constexpr std::uint16_t kDefaultVelocityIGain = 1920;
constexpr std::uint16_t kDefaultVelocityPGain = 100;
constexpr std::uint16_t kDefaultPositionPGain = 800;
constexpr std::uint8_t kDefaultSecondaryId = 255;  // off
constexpr std::uint8_t kDefaultProtocolType = 2;
constexpr std::uint16_t kDefaultMaxVoltage = 160;
constexpr std::uint16_t kDefaultMinVoltage = 95;
constexpr std::uint16_t kDefaultPwmLimit = 885;
constexpr std::uint16_t kDefaultCurrentLimit = 1193;

constexpr std::uint8_t kDefaultMovingThreshold = 10;
constexpr std::uint8_t kDefaultTemperatureLimit = 80;
constexpr std::uint8_t kDefaultShutdown = 0x34;  // overload, electrical shock, overheating

double ticks_per_s_to_units(double ticks_per_s) {
  return ticks_per_s / kXTicksPerRev * 60.0 / kXVelocityUnitRpm;
}

}  // namespace

std::uint8_t baud_rate_register(int baud) { return baud_register(kDynamixelX, baud); }

double initial_offset_rad(int device_id) {
  const double degrees = (device_id % 2 == 1 ? 1.0 : -1.0) * (2 + device_id % 3);
  return degrees * std::numbers::pi / 180.0;
}

double initial_position_rad(const ActuatorBinding& binding) {
  const double offset = initial_offset_rad(binding.device_id);
  if (!binding.has_limits()) return offset;
  return std::clamp(offset, binding.min_position, binding.max_position);
}

DynamixelServo::DynamixelServo(const ActuatorBinding& binding, const SimBusSettings& settings,
                               int baud, Nanos now, JointPhysics* physics)
    : binding_(binding),
      tau_s_(std::max(0.0, settings.time_constant_s)),
      vmax_ticks_s_(std::max(0.0, settings.max_speed_rad_s * binding.ticks_per_rad)),
      motor_time_(now),
      physics_(physics),
      health_(settings.health, binding.device_id, now) {
  if (physics_ != nullptr) {
    physics_joint_ = physics_->joint_index(binding.joint);
    if (physics_joint_ < 0) {
      throw InputError({}, "actuator",
                       "joint '" + elide(binding.joint) + "' is not driven by the physics model");
    }
  }
  // EEPROM at its defaults, shaped by the bus config.
  const std::uint16_t model = dxl::device_options(binding).model_number;
  dxl::put_u16(&table_[xreg::model_number], model != 0 ? model : kXModelNumber);
  table_[xreg::firmware_version] = static_cast<std::uint8_t>(
      settings.firmware_version > 0 ? settings.firmware_version : kXFirmwareVersion);
  table_[xreg_sim::secondary_id] = kDefaultSecondaryId;
  table_[xreg_sim::protocol_type] = kDefaultProtocolType;
  dxl::put_u16(&table_[xreg_sim::max_voltage_limit], kDefaultMaxVoltage);
  dxl::put_u16(&table_[xreg_sim::min_voltage_limit], kDefaultMinVoltage);
  dxl::put_u16(&table_[xreg_sim::pwm_limit], kDefaultPwmLimit);
  dxl::put_u16(&table_[xreg_sim::current_limit], kDefaultCurrentLimit);
  table_[xreg::id] = static_cast<std::uint8_t>(binding.device_id);
  table_[xreg::baud_rate] = baud_rate_register(baud);
  table_[xreg::return_delay_time] =
      static_cast<std::uint8_t>(std::clamp(settings.return_delay_us / 2, 0, 254));
  table_[xreg::operating_mode] = 3;
  dxl::put_u32(&table_[xreg_sim::moving_threshold], kDefaultMovingThreshold);
  table_[xreg_sim::temperature_limit] = kDefaultTemperatureLimit;
  const double limit_units = std::ceil(ticks_per_s_to_units(vmax_ticks_s_));
  dxl::put_u32(&table_[xreg::velocity_limit],
               static_cast<std::uint32_t>(std::clamp(limit_units, 0.0, 1023.0)));
  dxl::put_u32(&table_[xreg::max_position_limit], 4095);
  dxl::put_u32(&table_[xreg::min_position_limit], 0);
  table_[xreg_sim::shutdown] = kDefaultShutdown;

  const std::int32_t start =
      std::clamp(binding.to_ticks(initial_position_rad(binding)), reg32(xreg::min_position_limit),
                 reg32(xreg::max_position_limit));
  motor_.position = start;
  if (physics_ != nullptr) motor_ = motor_at(now);  // where the physics put the joint
  eeprom_.build(table_);
  reset_ram();
  publish(now);
  command_physics();
}

void DynamixelServo::command_physics() {
  if (physics_ == nullptr) return;
  physics_->command(physics_joint_, binding_.to_rad(motor_goal()), torque_on());
}

std::int32_t DynamixelServo::motor_goal() const {
  std::int32_t goal = reg32(xreg::goal_position);
  if (!multi_turn(table_[xreg::operating_mode])) {
    goal = std::clamp(goal, reg32(xreg::min_position_limit), reg32(xreg::max_position_limit));
  }
  return goal - reg32(xreg_sim::homing_offset) + turn_base_;
}

std::int32_t DynamixelServo::present_of(double motor_ticks) const {
  return static_cast<std::int32_t>(std::lround(motor_ticks)) - turn_base_ +
         reg32(xreg_sim::homing_offset);
}

void DynamixelServo::count_from_single_turn() {
  const auto turn = static_cast<std::int64_t>(kXTicksPerRev);
  const auto ticks = static_cast<std::int64_t>(std::lround(motor_.position));
  // floor, also below zero: the count starts at the shaft's angle within its turn
  const std::int64_t turns = ticks >= 0 ? ticks / turn : -((-ticks + turn - 1) / turn);
  turn_base_ = static_cast<std::int32_t>(turns * turn);
}

std::int32_t DynamixelServo::reg32(std::uint16_t address) const {
  return static_cast<std::int32_t>(dxl::get_u32(&table_[address]));
}

void DynamixelServo::reset_ram() {
  std::fill(table_.begin() + xreg_sim::eeprom_end, table_.end(), std::uint8_t{0});
  table_[xreg::status_return_level] = 2;
  dxl::put_u16(&table_[xreg_sim::velocity_i_gain], kDefaultVelocityIGain);
  dxl::put_u16(&table_[xreg_sim::velocity_p_gain], kDefaultVelocityPGain);
  dxl::put_u16(&table_[xreg_sim::position_p_gain], kDefaultPositionPGain);
  // Indirect Address n starts at Indirect Data n itself.
  for (std::uint16_t k = 0; k < xreg::indirect_count; ++k) {
    dxl::put_u16(&table_[xreg::indirect_address_1 + 2 * k],
                 static_cast<std::uint16_t>(xreg::indirect_data_1 + k));
    dxl::put_u16(&table_[xreg::indirect_address_29 + 2 * k],
                 static_cast<std::uint16_t>(xreg::indirect_data_29 + k));
  }
  // Hold still when torque comes on: the goal starts at the present position.
  dxl::put_u32(&table_[xreg::goal_position],
               static_cast<std::uint32_t>(present_of(motor_.position)));
  motor_.velocity = 0;
  pending_length_ = 0;
  held_by_hand_ = false;
}

void DynamixelServo::latch_shutdown() {
  shut_down_ = true;
  table_[xreg::torque_enable] = 0;
}

DynamixelServo::Motor DynamixelServo::motor_at(Nanos now) const {
  // Where advance() will find it: held from the moment the watchdog fires.
  if (const Nanos due = watchdog_fire_time(); physics_ == nullptr && due >= 0 && now > due) {
    Motor m = motor_until(std::max(due, motor_time_));
    m.position = std::round(m.position);  // held at the goal it takes: a whole tick
    m.velocity = 0;
    return m;
  }
  return motor_until(now);
}

DynamixelServo::Motor DynamixelServo::motor_until(Nanos now) const {
  Motor m = motor_;
  if (physics_ != nullptr) {
    const double scale = binding_.direction * binding_.ticks_per_rad;
    m.position = binding_.zero_ticks + scale * physics_->position(physics_joint_);
    m.velocity = scale * physics_->velocity(physics_joint_);
    return m;
  }
  // Blocked, or a hand holds it against a weak torque: held where it is.
  if (!torque_on() || vmax_ticks_s_ <= 0 || health_.blocked() || held_by_hand_) {
    m.velocity = 0;
    return m;
  }
  if (now <= motor_time_) return m;
  // Limits may have changed while torque was off; the servo never leaves them.
  return m.after(to_seconds(now - motor_time_), motor_goal(), vmax_ticks_s_, tau_s_);
}

Nanos DynamixelServo::watchdog_fire_time() const {
  const std::uint8_t units = table_[xreg_sim::bus_watchdog];
  if (units == 0 || units == dxl::kBusWatchdogFired || !torque_on()) return -1;
  return watchdog_fed_ + static_cast<Nanos>(units) * kBusWatchdogUnitNs;
}

void DynamixelServo::feed_watchdog(Nanos now) { watchdog_fed_ = std::max(watchdog_fed_, now); }

void DynamixelServo::advance(Nanos now) {
  if (now < motor_time_) return;
  // The watchdog fires at its own time, however late the next packet comes:
  // the motor runs to that moment and stops there.
  if (const Nanos due = watchdog_fire_time(); due >= 0 && now > due) {
    const Nanos fire = std::max(due, motor_time_);
    if (physics_ != nullptr) physics_->advance(fire);
    motor_ = motor_at(fire);
    motor_time_ = fire;
    // It stops where it is (Profile Velocity/Acceleration taken as 0) and
    // keeps torque on; the goal values are locked until 98 is written 0.
    if (physics_ == nullptr) motor_.position = std::round(motor_.position);
    dxl::put_u32(&table_[xreg::goal_position],
                 static_cast<std::uint32_t>(present_of(motor_.position)));
    motor_.velocity = 0;
    table_[xreg_sim::bus_watchdog] = dxl::kBusWatchdogFired;
    publish(fire);
    command_physics();
  }
  if (physics_ != nullptr) physics_->advance(now);
  motor_ = motor_at(now);
  motor_time_ = now;
  health_.advance(now, motor_.velocity / binding_.ticks_per_rad, torque_on());
  publish(now);
}

void DynamixelServo::publish(Nanos now) {
  const std::int32_t position = present_of(motor_.position);
  const auto velocity =
      static_cast<std::int32_t>(std::lround(ticks_per_s_to_units(motor_.velocity)));
  dxl::put_u32(&table_[xreg::present_position], static_cast<std::uint32_t>(position));
  dxl::put_u32(&table_[xreg::present_velocity], static_cast<std::uint32_t>(velocity));
  table_[xreg::moving] = std::abs(velocity) > reg32(xreg_sim::moving_threshold) ? 1 : 0;
  const Nanos ms = now / 1'000'000;
  dxl::put_u16(&table_[xreg_sim::realtime_tick], static_cast<std::uint16_t>(ms % 32768));
  // Current signed like the motion, in the XM430's unit (2.69 mA).
  const double amps = health_.current_a() * (motor_.velocity < 0 ? -1.0 : 1.0);
  dxl::put_u16(&table_[xreg_sim::present_current],
               static_cast<std::uint16_t>(static_cast<std::int16_t>(
                   std::clamp(std::lround(amps / kXCurrentUnitA), -32767L, 32767L))));
  dxl::put_u16(
      &table_[xreg_sim::present_input_voltage],
      static_cast<std::uint16_t>(std::clamp(std::lround(10.0 * health_.voltage_v()), 0L, 65535L)));
  table_[xreg::present_temperature] =
      static_cast<std::uint8_t>(std::clamp(std::lround(health_.temperature_c()), 0L, 255L));
  // The firmware's own checks against its limits, as the Hardware Error
  // Status bits; one in Shutdown switches torque off until a Reboot.
  const std::uint8_t model_bits = health_.error_bits(
      table_[xreg_sim::temperature_limit], 0.1 * dxl::get_u16(&table_[xreg_sim::min_voltage_limit]),
      0.1 * dxl::get_u16(&table_[xreg_sim::max_voltage_limit]));
  const std::uint8_t bits = static_cast<std::uint8_t>(injected_error_ | model_bits);
  if ((bits & table_[xreg_sim::shutdown]) != 0 && !shut_down_) latch_shutdown();
  table_[xreg::hardware_error_status] = bits;
  table_[xreg_sim::registered_instruction] = pending_length_ > 0 ? 1 : 0;
}

StatusError DynamixelServo::read(std::uint16_t address, std::uint16_t length,
                                 std::span<std::uint8_t> out) const {
  if (length == 0 || out.size() < length) return StatusError::data_length;
  if (static_cast<std::size_t>(address) + length > table_.size()) return StatusError::access;
  bool position = false;
  for (std::size_t i = 0; i < length; ++i) {
    const std::uint16_t at = resolve(address + i);
    out[i] = table_[at];
    position = position || (at >= xreg::present_position && at < xreg::present_position + 4);
  }
  if (position) ++position_reads_;
  return StatusError::none;
}

std::uint16_t DynamixelServo::resolve(std::size_t address) const {
  if (in_block(address, xreg::indirect_data_1, 1)) {
    return dxl::get_u16(&table_[xreg::indirect_address_1 + 2 * (address - xreg::indirect_data_1)]);
  }
  if (in_block(address, xreg::indirect_data_29, 1)) {
    return dxl::get_u16(
        &table_[xreg::indirect_address_29 + 2 * (address - xreg::indirect_data_29)]);
  }
  return static_cast<std::uint16_t>(address);
}

bool DynamixelServo::fast_read() const {
  return dxl::supports_fast_read(model_number(), firmware_version());
}

// Calls f(target, bytes) for each run of bytes whose target registers are
// consecutive (one run for a write without Indirect Data).
template <typename F>
void for_each_run(const DynamixelServo& servo, std::uint16_t address,
                  std::span<const std::uint8_t> data, F&& f) {
  std::size_t i = 0;
  while (i < data.size()) {
    const std::uint16_t start = servo.resolve(address + i);
    std::size_t n = 1;
    while (i + n < data.size() && servo.resolve(address + i + n) == start + n) ++n;
    f(start, data.subspan(i, n));
    i += n;
  }
}

StatusError DynamixelServo::check_write(std::uint16_t address,
                                        std::span<const std::uint8_t> data) const {
  if (data.empty()) return StatusError::data_length;
  if (address + data.size() > table_.size()) return StatusError::access;
  StatusError error = StatusError::none;
  for_each_run(*this, address, data, [&](std::uint16_t target, std::span<const std::uint8_t> run) {
    if (error == StatusError::none) error = check_direct(target, run);
  });
  return error;
}

StatusError DynamixelServo::check_direct(std::uint16_t address,
                                         std::span<const std::uint8_t> data) const {
  const std::size_t end = address + data.size();
  if (end > table_.size()) return StatusError::access;
  // Whole writable items only: a gap or read-only item is an Access Error, a
  // part of an item a Data Length Error (as the Protocol 2.0 page defines).
  for (std::size_t a = address; a < end;) {
    Item item{};
    if (!find_item(a, item)) return StatusError::access;
    if (!item.writable) return StatusError::access;
    if (item.address != a || a + item.size > end) return StatusError::data_length;
    a += item.size;
  }
  if (eeprom_write(kDynamixelX, table_, address, data.size()) == EepromWrite::refused) {
    return StatusError::access;  // EEPROM is locked while torque is on
  }
  if (table_[xreg_sim::bus_watchdog] == dxl::kBusWatchdogFired) {
    // A fired Bus Watchdog locks the goal values; only 0 at 98 clears it.
    for (std::size_t a = address; a < end;) {
      Item item{};
      find_item(a, item);
      if (item.address == xreg_sim::goal_pwm || item.address == xreg_sim::goal_current ||
          item.address == xreg_sim::goal_velocity || item.address == xreg::goal_position ||
          (item.address == xreg_sim::bus_watchdog && data[a - address] != 0)) {
        return StatusError::data_range;
      }
      a += item.size;
    }
  }

  std::array<std::uint8_t, dxl::xreg::table_size> after = table_;
  std::memcpy(&after[address], data.data(), data.size());
  for (std::size_t a = address; a < end;) {
    Item item{};
    find_item(a, item);
    const std::uint32_t raw = get_le(&after[a], item.size);
    if (item.address == xreg::goal_position) {
      const auto goal = static_cast<std::int32_t>(raw);
      if (multi_turn(after[xreg::operating_mode])) {
        if (goal < -kExtendedPositionRange || goal > kExtendedPositionRange) {
          return StatusError::data_limit;
        }
      } else if (goal < static_cast<std::int32_t>(dxl::get_u32(&after[xreg::min_position_limit])) ||
                 goal > static_cast<std::int32_t>(dxl::get_u32(&after[xreg::max_position_limit]))) {
        return StatusError::data_limit;
      }
    } else if (const std::int64_t v = item_value(item, raw); v < item.min || v > item.max) {
      return StatusError::data_range;
    }
    a += item.size;
  }
  // After a shutdown only a Reboot allows torque on again.
  if (shut_down_ && after[xreg::torque_enable] != 0) return StatusError::result_fail;
  return StatusError::none;
}

StatusError DynamixelServo::write(std::uint16_t address, std::span<const std::uint8_t> data) {
  const StatusError error = check_write(address, data);
  if (address + data.size() > table_.size()) {
    log_goal(address, data, false);
    return error;
  }
  for_each_run(*this, address, data, [&](std::uint16_t target, std::span<const std::uint8_t> run) {
    log_goal(target, run, error == StatusError::none);
  });
  if (error != StatusError::none) return error;
  // Resolved before any byte lands: a write may change an Indirect Address
  // and an Indirect Data at once; the data goes where the old address said.
  std::array<std::uint16_t, xreg::table_size> targets;
  for (std::size_t i = 0; i < data.size(); ++i) targets[i] = resolve(address + i);
  const bool eeprom = eeprom_write(kDynamixelX, table_, address, data.size()) == EepromWrite::kept;
  const std::uint8_t mode_before = table_[xreg::operating_mode];
  const bool torque_before = torque_on();
  for (std::size_t i = 0; i < data.size(); ++i) table_[targets[i]] = data[i];
  // Position control mode counts within one turn: entered, or torque on in
  // it, the count starts again from the shaft's angle.
  const bool position_mode = table_[xreg::operating_mode] == kPositionMode;
  if (position_mode && (mode_before != kPositionMode || (!torque_before && torque_on()))) {
    count_from_single_turn();
  }
  if (eeprom) eeprom_.keep(table_);
  if (!torque_on() && physics_ == nullptr) motor_.velocity = 0;
  let_go_of_hand();
  publish(motor_time_);  // a torque change shows in Present Velocity and Moving at once
  command_physics();
  return StatusError::none;
}

StatusError DynamixelServo::reg_write(std::uint16_t address, std::span<const std::uint8_t> data) {
  const StatusError error = check_write(address, data);
  if (error != StatusError::none) return error;
  std::memcpy(pending_.data(), data.data(), data.size());
  pending_address_ = address;
  pending_length_ = static_cast<std::uint16_t>(data.size());
  table_[xreg_sim::registered_instruction] = 1;
  return StatusError::none;
}

StatusError DynamixelServo::action() {
  if (pending_length_ == 0) return StatusError::instruction;  // Action without Reg Write
  const std::uint16_t length = pending_length_;
  pending_length_ = 0;
  table_[xreg_sim::registered_instruction] = 0;
  return write(pending_address_, {pending_.data(), length});
}

void DynamixelServo::reboot(Nanos now) {
  advance(now);
  // The encoder knows one turn: a power-up counts from the shaft's angle in it.
  count_from_single_turn();
  shut_down_ = false;
  reset_ram();
  if (injected_error_ & table_[xreg_sim::shutdown]) latch_shutdown();
  publish(motor_time_);
  command_physics();
}

void DynamixelServo::set_plugged(bool plugged, Nanos now) {
  if (plugged && !plugged_) {
    eeprom_.load(table_);  // power-on: EEPROM as kept, RAM at its defaults
    reboot(now);
  }
  plugged_ = plugged;
}

void DynamixelServo::factory_reset(std::uint8_t option, Nanos now) {
  eeprom_.factory_reset(table_, option == 0x01 || option == 0x02, option == 0x02);
  table_[xreg::torque_enable] = 0;
  reboot(now);
}

bool DynamixelServo::restore_eeprom(std::span<const std::uint8_t> kept, Nanos now) {
  if (!eeprom_.restore(kept, table_)) return false;
  table_[xreg::torque_enable] = 0;
  reboot(now);
  return true;
}

bool DynamixelServo::yields_to_hand() const {
  if (!torque_on()) return true;
  if (table_[xreg::operating_mode] != kCurrentBasedPositionMode) return false;
  const auto goal = static_cast<std::int16_t>(dxl::get_u16(&table_[xreg_sim::goal_current]));
  const double limit = dxl::get_u16(&table_[xreg_sim::current_limit]);
  return std::abs(goal) <= kHandOverpowersShare * limit;
}

void DynamixelServo::let_go_of_hand() {
  if (!held_by_hand_) return;
  const bool pulls_away = std::abs(motor_goal() - motor_.position) > kHandLetsGoTicks;
  if (!torque_on() || !yields_to_hand() || !pulls_away) held_by_hand_ = false;
}

bool DynamixelServo::hand_move(std::int32_t ticks, Nanos now) {
  advance(now);
  if (!yields_to_hand() || physics_ != nullptr) return false;
  motor_.position = ticks - reg32(xreg_sim::homing_offset) + turn_base_;
  motor_.velocity = 0;
  // Against a weak torque the hand holds the joint until the servo's goal
  // comes to it; a limp joint simply stays.
  held_by_hand_ = torque_on();
  let_go_of_hand();
  publish(motor_time_);
  return true;
}

std::int32_t DynamixelServo::present_ticks(Nanos now) const {
  return present_of(motor_at(std::max(now, motor_time_)).position);
}

int DynamixelServo::baud() const { return baud_of(kDynamixelX, table_[xreg::baud_rate]); }

std::uint8_t DynamixelServo::status_error(StatusError error) const {
  const auto number = static_cast<std::uint8_t>(error);
  return table_[xreg::hardware_error_status] != 0 ? (dxl::kAlertBit | number) : number;
}

void DynamixelServo::set_hardware_error(std::uint8_t bits, Nanos now) {
  advance(now);
  injected_error_ = bits;
  if (bits & table_[xreg_sim::shutdown]) latch_shutdown();
  if (!torque_on() && physics_ == nullptr) motor_.velocity = 0;
  publish(motor_time_);
  command_physics();
}

void DynamixelServo::log_goal(std::uint16_t address, std::span<const std::uint8_t> data,
                              bool accepted) {
  const std::size_t goal = xreg::goal_position;
  if (address > goal || address + data.size() < goal + 4) return;
  if (goal_ring_.empty()) goal_ring_.resize(kGoalLogCapacity);
  GoalRecord& r = goal_ring_[goals_received_ % kGoalLogCapacity];
  r.time = motor_time_;
  r.ticks = static_cast<std::int32_t>(dxl::get_u32(data.data() + (goal - address)));
  r.rad = binding_.to_rad(r.ticks);
  r.accepted = accepted;
  ++goals_received_;
}

std::vector<GoalRecord> DynamixelServo::goal_log() const {
  const std::uint64_t kept = std::min<std::uint64_t>(goals_received_, kGoalLogCapacity);
  std::vector<GoalRecord> out;
  out.reserve(kept);
  for (std::uint64_t k = goals_received_ - kept; k < goals_received_; ++k) {
    out.push_back(goal_ring_[k % kGoalLogCapacity]);
  }
  return out;
}

void DynamixelServo::clear_goal_log() { goals_received_ = 0; }

void DynamixelServo::set_answer_delay(Nanos delay_ns, int answers) {
  answer_delay_ns_ = std::max<Nanos>(0, delay_ns);
  delayed_answers_left_ = answers;
}

Nanos DynamixelServo::take_answer_delay() const {
  if (answer_delay_ns_ == 0 || delayed_answers_left_ == 0) return 0;
  if (delayed_answers_left_ > 0) --delayed_answers_left_;
  return answer_delay_ns_;
}

double DynamixelServo::position_rad(Nanos now) const {
  const Motor m = motor_at(std::max(now, motor_time_));
  const double present = m.position - turn_base_ + reg32(xreg_sim::homing_offset);
  return binding_.direction * (present - binding_.zero_ticks) / binding_.ticks_per_rad;
}

}  // namespace animrt::sim
