#pragma once
// Simulated Feetech STS/SCS servos of one bus answering decoded instruction
// packets as their firmware would. No I/O: status packets go to an Answers
// list in the order they appear on the wire.
//
// Each servo keeps the memory table (reg:: in feetech_codec.hpp, values in
// the series' byte order): ID, Baud Rate, Return Delay, Status Return
// Level, Min/Max Angle Limit, Unload Condition, Torque Enable, Acceleration,
// Goal Position/Time/Speed, the EEPROM lock, Present Position/Speed/Load/
// Voltage/Temperature, Registered, Servo Status, Moving. Writes to read-only
// addresses change nothing (the servo has no error code for that; its error
// byte only carries fault bits). EEPROM (below 40) is kept across power
// cycles only when written while the lock reads 0 (servo_eeprom.hpp).
//
// Instructions: Ping, Read, Write, Reg Write, Action, Sync Write, and Sync
// Read on the STS series only (an SCS servo ignores it). Ping and Read are
// always answered; Write, Reg Write and Action only with Status Return
// Level 1 and a unicast id. Broadcast packets other than Ping are never
// answered. A servo that is not responding ignores every packet.
//
// Motor: as the Dynamixel simulation, with torque on Present Position
// follows Goal Position (clamped into the angle limits) as a first-order lag
// with time constant tau whose speed is limited to vmax, integrated in
// closed form. A fault injected with bits in Unload Condition switches
// torque off; the error byte of every status packet carries the fault bits.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/sim/servo_answers.hpp"
#include "animrt/sim/servo_eeprom.hpp"
#include "animrt/sim/servo_health_model.hpp"
#include "animrt/sim/servo_motor.hpp"

namespace animrt::sim {

// Status packets for one instruction packet (servo_answers.hpp).
using FeetechAnswers = Answers;

class FeetechServo {
 public:
  FeetechServo(const ActuatorBinding& binding, ft::Series series, const SimBusSettings& settings,
               int baud, Nanos now);

  int device_id() const { return binding_.device_id; }  // as configured
  std::uint8_t id() const { return table_[ft::reg::id]; }
  bool torque_on() const { return table_[ft::reg::torque_enable] != 0; }
  int return_delay_us() const { return 2 * table_[ft::reg::return_delay]; }
  std::uint8_t status_return_level() const { return table_[ft::reg::status_return_level]; }
  std::uint8_t error_byte() const { return table_[ft::reg::servo_status]; }

  void advance(Nanos now);
  // False if the range is outside the table.
  bool read(std::uint8_t address, std::uint8_t length, std::span<std::uint8_t> out) const;
  void write(std::uint8_t address, std::span<const std::uint8_t> data);
  void reg_write(std::uint8_t address, std::span<const std::uint8_t> data);
  void action();

  // Takes in packets: responding, plugged in, at the packet's baud rate.
  bool responding() const { return responding_ && plugged_ && hearing_; }
  void set_hearing(bool hearing) { hearing_ = hearing; }
  void set_responding(bool responding) { responding_ = responding; }
  void set_fault(std::uint8_t bits, Nanos now);
  // Current, supply and temperature (servo_health_model.hpp).
  ServoHealthModel& health() { return health_; }

  // Commissioning, as DynamixelServo: unplugged it hears and says nothing,
  // plugged in again it powers up (torque off, goal at the present
  // position); a hand turns a limp shaft (false while torque is on).
  void set_plugged(bool plugged, Nanos now);
  // A hand turns a limp shaft, or one held by a weak torque (STS Torque
  // Limit at most 250, a quarter), which it then holds against the servo
  // until the servo's goal comes within 4 steps of it or the torque goes off
  // or up. False, and nothing moves, against a stronger torque.
  bool hand_move(std::int32_t steps, Nanos now);
  bool yields_to_hand() const;
  int baud() const;  // the Baud Rate register in bits per second
  std::int32_t present_steps(Nanos now) const;
  // EEPROM (0..39): a write there is kept while the lock (STS 55, SCS 48)
  // reads 0, otherwise lost at the next power-up (servo_eeprom.hpp).
  const ServoEeprom& eeprom() const { return eeprom_; }
  bool restore_eeprom(std::span<const std::uint8_t> kept, Nanos now);
  void factory_reset(Nanos now);  // all of it, ID and baud rate included

  // Goal positions received (decoded, in steps), for tests.
  std::uint64_t goals_received() const { return goals_received_; }
  std::int32_t last_goal() const { return last_goal_; }
  std::int32_t goal_position() const;
  double position_rad(Nanos now) const;

 private:
  using Motor = ServoMotor;  // steps, steps/s
  Motor motor_at(Nanos now) const;
  void publish();
  std::int32_t position_value(std::uint8_t address) const;
  void store_position(std::uint8_t address, double steps);
  void power_up(Nanos now);  // RAM at its defaults, EEPROM as kept
  void let_go_of_hand();     // after a write: the hand holds on only against a weak pull
  bool held_by_hand_ = false;
  std::uint16_t u16(std::uint8_t address) const;

  ActuatorBinding binding_;
  ft::Series series_;
  double tau_s_;
  double vmax_steps_s_;
  std::array<std::uint8_t, ft::reg::table_size> table_{};
  ServoEeprom eeprom_;
  Motor motor_;
  Nanos motor_time_;
  ServoHealthModel health_;
  std::uint8_t injected_ = 0;  // set_fault()'s bits
  bool responding_ = true;
  bool plugged_ = true;
  bool hearing_ = true;
  std::array<std::uint8_t, ft::reg::table_size> pending_{};
  std::uint8_t pending_address_ = 0;
  std::uint8_t pending_length_ = 0;
  std::uint64_t goals_received_ = 0;
  std::int32_t last_goal_ = 0;
};

class FeetechBoard {
 public:
  // One servo per actuator of `config`. Throws InputError for an id outside
  // 0..253 or used twice.
  FeetechBoard(const BusConfig& config, ft::Series series, Nanos now);

  // As DynamixelFirmware::handle: only servos at `line_baud` (0: all) hear
  // the packet; servos sharing an ID all act and their answers collide.
  void handle(const ft::Packet& packet, Nanos now, FeetechAnswers& out, int line_baud = 0);

  FeetechServo* find_configured(int device_id);
  const FeetechServo* find_configured(int device_id) const;
  std::size_t size() const { return servos_.size(); }
  FeetechServo& at(std::size_t index) { return servos_.at(index); }
  ft::Series series() const { return series_; }

 private:
  template <class Act>
  void for_id(std::uint8_t id, FeetechAnswers& out, Act&& act);
  void answer(const FeetechServo& servo, std::span<const std::uint8_t> data,
              FeetechAnswers& out) const;

  ft::Series series_;
  std::vector<FeetechServo> servos_;
};

// Whether any servo may answer this packet (broadcasts other than Ping and
// Sync Read never get one).
bool feetech_may_answer(const ft::Packet& packet);

}  // namespace animrt::sim
