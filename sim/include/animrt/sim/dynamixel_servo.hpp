#pragma once
// One simulated Dynamixel X-series servo: its control table, the firmware's
// rules for reading and writing it, and a motor model. No I/O;
// DynamixelFirmware feeds it packets. Identity: the model of the actuator's
// `model` key (default XM430-W210, model 1030) and the bus's
// sim.firmware_version (default 38, as in the manual's Ping example).
//
// Control table: the X430 table (addresses 0..661, kItems in
// dynamixel_servo.cpp); addresses without an item read as 0 and cannot be
// written (Access Error); reads and writes past 661 are Access Errors.
// EEPROM items (below 64; servo_eeprom.hpp keeps them across Reboot, power
// cycles and state files) refuse writes while torque is on (Access Error),
// read-only items refuse every write (Access Error), a write of part of an
// item is a Data Length Error, a value outside the item's range a Data Range
// Error. Indirect Data n reads and writes the register Indirect Address n
// names (64..661), under that register's rules; a write that covers several
// Indirect Data maps to one write per run of consecutive target addresses,
// all checked before any is applied.
// Modelled items: ID, Baud Rate, Return Delay Time, Operating Mode (3,
// position control; 4, extended position control: Goal Position
// +-1,048,575 and no position limits; 5, current-based position control:
// as 4, and Goal Current limits the torque, see the hand below; other
// modes answer Data Range Error),
// Homing Offset (Present and Goal Position are the motor's position plus
// it), the count of turns (Present Position counts on across turns in any
// mode while torque is off; it starts again from the shaft's angle within
// one turn, 0..4095, at power-up and Reboot, when Operating Mode becomes 3
// and when torque comes on in mode 3), Moving Threshold,
// Velocity Limit, Min/Max Position Limit, Shutdown, Torque Enable, LED, Status
// Return Level, Registered Instruction, Hardware Error Status, Goal Position,
// Realtime Tick, Moving, Present Velocity/Position/Input Voltage/Temperature.
// Stored but without effect: every other item, e.g. Drive Mode, Temperature
// Limit, the gains, Profile Acceleration/Velocity, Velocity Limit (the rate
// limit is SimBusSettings::max_speed_rad_s).
//
// Bus Watchdog (98, units of 20 ms), while torque is on: when no instruction
// packet reached the servo (its id or broadcast: feed_watchdog) for longer
// than the set time, the servo stops where it is at that moment, keeps torque
// on, and 98 reads 0xFF (-1); Goal PWM/Current/Velocity/Position then answer
// Data Range Error until 0 is written to 98. Judged on the time the firmware
// is given (a lockstep run's clock), at that instant however late the next
// packet arrives.
//
// Motor: with torque on, Present Position follows Goal Position as a first
// order lag (time constant tau) whose speed is limited to vmax: speed =
// clamp((goal - position) / tau, -vmax, vmax). The model is integrated in
// closed form, so the state at time t does not depend on how often it was
// advanced on the way (packets may arrive at any rate). Torque off: no motion.
//
// With a JointPhysics the motor model is the physics instead: the servo hands
// it the goal (within the position limits) and the torque state whenever
// they change, steps it on to each packet's time, and publishes the joint's
// position and velocity (a limp joint can be moved by the physics).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/sim/joint_physics.hpp"
#include "animrt/sim/servo_eeprom.hpp"
#include "animrt/sim/servo_health_model.hpp"
#include "animrt/sim/servo_motor.hpp"

namespace animrt::sim {

// X-series addresses the simulator uses beyond dxl::xreg.
namespace xreg_sim {
inline constexpr std::uint16_t model_information = 2;        // 4
inline constexpr std::uint16_t drive_mode = 10;              // 1
inline constexpr std::uint16_t secondary_id = 12;            // 1
inline constexpr std::uint16_t protocol_type = 13;           // 1
inline constexpr std::uint16_t homing_offset = 20;           // 4, signed
inline constexpr std::uint16_t moving_threshold = 24;        // 4, unit 0.229 rpm
inline constexpr std::uint16_t temperature_limit = 31;       // 1
inline constexpr std::uint16_t max_voltage_limit = 32;       // 2, unit 0.1 V
inline constexpr std::uint16_t min_voltage_limit = 34;       // 2
inline constexpr std::uint16_t pwm_limit = 36;               // 2
inline constexpr std::uint16_t current_limit = 38;           // 2
inline constexpr std::uint16_t startup_configuration = 60;   // 1
inline constexpr std::uint16_t shutdown = 63;                // 1
inline constexpr std::uint16_t registered_instruction = 69;  // 1
inline constexpr std::uint16_t velocity_i_gain = 76;         // 2
inline constexpr std::uint16_t velocity_p_gain = 78;         // 2
inline constexpr std::uint16_t position_d_gain = 80;         // 2
inline constexpr std::uint16_t position_i_gain = 82;         // 2
inline constexpr std::uint16_t position_p_gain = 84;         // 2
inline constexpr std::uint16_t feedforward_2nd_gain = 88;    // 2
inline constexpr std::uint16_t feedforward_1st_gain = 90;    // 2
inline constexpr std::uint16_t bus_watchdog = 98;            // 1
inline constexpr std::uint16_t goal_pwm = 100;               // 2, signed
inline constexpr std::uint16_t goal_current = 102;           // 2, signed
inline constexpr std::uint16_t goal_velocity = 104;          // 4, signed
inline constexpr std::uint16_t profile_acceleration = 108;   // 4
inline constexpr std::uint16_t profile_velocity = 112;       // 4
inline constexpr std::uint16_t realtime_tick = 120;          // 2, ms modulo 32768
inline constexpr std::uint16_t moving_status = 123;          // 1
inline constexpr std::uint16_t present_pwm = 124;            // 2
inline constexpr std::uint16_t present_current = 126;        // 2
inline constexpr std::uint16_t velocity_trajectory = 136;    // 4
inline constexpr std::uint16_t position_trajectory = 140;    // 4
inline constexpr std::uint16_t present_input_voltage = 144;  // 2, unit 0.1 V
inline constexpr std::uint16_t backup_ready = 147;           // 1
inline constexpr std::uint16_t eeprom_end = 64;              // first RAM address
}  // namespace xreg_sim

inline constexpr std::uint16_t kXModelNumber = 1030;  // XM430-W210, when no model is given
inline constexpr std::uint8_t kXFirmwareVersion = 38;
inline constexpr double kXTicksPerRev = 4096.0;
inline constexpr double kXVelocityUnitRpm = 0.229;
inline constexpr std::uint8_t kXTemperatureC = 36;
inline constexpr Nanos kBusWatchdogUnitNs = 20'000'000;
inline constexpr std::uint16_t kXInputVoltage = 120;  // 12.0 V
inline constexpr double kXCurrentUnitA = 0.00269;     // Present Current unit (XM430)

// Baud Rate register value for a baud (9600 -> 0, 57600 -> 1, 115200 -> 2,
// 1M -> 3, 2M -> 4, 3M -> 5, 4M -> 6, 4.5M -> 7); the nearest one otherwise.
std::uint8_t baud_rate_register(int baud);

// Initial position offset of a servo, so the runtime's start ramp has work to
// do: (2 + id % 3) degrees, positive for odd ids and negative for even ones.
double initial_offset_rad(int device_id);

// Where a simulated device of this binding starts: initial_offset_rad moved
// into the joint's limits when it has limits (a joint whose limits exclude
// the offset, e.g. a jaw of 0..30 deg, starts at the nearest limit), so the
// runtime's bring-up never meets a pose the config forbids.
double initial_position_rad(const ActuatorBinding& binding);

// One Goal Position the servo received (Write, Reg Write + Action, Sync or
// Bulk Write), as it arrived.
struct GoalRecord {
  Nanos time = 0;          // the servo's time when the packet took effect
  std::int32_t ticks = 0;  // the value written
  double rad = 0.0;        // the same through the binding
  bool accepted = false;   // false: refused (e.g. outside Min/Max Position Limit)
};

class DynamixelServo {
 public:
  // The goal log keeps the latest this many goals (a ring, allocated once).
  static constexpr std::size_t kGoalLogCapacity = 16384;

  // `physics` (optional, outlives the servo) replaces the motor model; it
  // must drive binding.joint (InputError otherwise).
  DynamixelServo(const ActuatorBinding& binding, const SimBusSettings& settings, int baud,
                 Nanos now, JointPhysics* physics = nullptr);

  int device_id() const { return binding_.device_id; }       // as configured
  std::uint8_t id() const { return table_[dxl::xreg::id]; }  // answers to this
  std::uint8_t status_return_level() const { return table_[dxl::xreg::status_return_level]; }
  int return_delay_us() const { return 2 * table_[dxl::xreg::return_delay_time]; }
  std::uint16_t model_number() const { return dxl::get_u16(&table_[dxl::xreg::model_number]); }
  std::uint8_t firmware_version() const { return table_[dxl::xreg::firmware_version]; }
  // Whether this model and firmware answer Fast Sync / Fast Bulk Read.
  bool fast_read() const;
  // The register an address stands for: itself, or for Indirect Data n the
  // address in Indirect Address n.
  std::uint16_t resolve(std::size_t address) const;
  bool torque_on() const { return table_[dxl::xreg::torque_enable] != 0; }

  // Brings the motor and the present-value registers to `now` (never back),
  // firing the Bus Watchdog on the way if its time came.
  void advance(Nanos now);
  // An instruction packet for this servo arrived at `now` (after advance).
  void feed_watchdog(Nanos now);
  // Whether the Bus Watchdog fired (98 reads 0xFF).
  bool watchdog_fired() const { return table_[xreg_sim::bus_watchdog] == dxl::kBusWatchdogFired; }

  // Instruction handlers. Each returns the error number for the status
  // packet; a failed write changes nothing. `out` must hold `length` bytes.
  dxl::StatusError read(std::uint16_t address, std::uint16_t length,
                        std::span<std::uint8_t> out) const;
  dxl::StatusError write(std::uint16_t address, std::span<const std::uint8_t> data);
  dxl::StatusError reg_write(std::uint16_t address, std::span<const std::uint8_t> data);
  dxl::StatusError action();
  void reboot(Nanos now);
  // Factory Reset: EEPROM to factory settings (option 0xFF: everything,
  // 0x01: all but the ID, 0x02: all but the ID and the baud rate), then a
  // restart as after Reboot.
  void factory_reset(std::uint8_t option, Nanos now);
  // The EEPROM that survives reboots and power cycles (servo_eeprom.hpp);
  // restore_eeprom puts one kept by a state file back (false: wrong size).
  const ServoEeprom& eeprom() const { return eeprom_; }
  bool restore_eeprom(std::span<const std::uint8_t> kept, Nanos now);

  // Error byte of a status packet: the number plus the alert bit while the
  // hardware error status is non-zero.
  std::uint8_t status_error(dxl::StatusError error) const;

  // Fault injection. A hardware error in Shutdown(63) (default: overheating,
  // electrical shock, overload) switches torque off; as on the real servo,
  // only a Reboot allows torque on again, and it shuts down again if the
  // fault is still there.
  // Takes in packets: responding (fault injection), plugged in, and at the
  // baud rate of the packet in hand (set_hearing).
  bool responding() const { return responding_ && plugged_ && hearing_; }
  void set_hearing(bool hearing) { hearing_ = hearing; }
  void set_responding(bool responding) { responding_ = responding; }
  void set_hardware_error(std::uint8_t bits, Nanos now);

  // Commissioning. Unplugged, the servo hears and says nothing; plugged in
  // again it powers up (RAM at its defaults, torque off). A hand turns a
  // limp shaft to raw `ticks`, or one held by a weak torque (current-based
  // position mode with Goal Current at most a quarter of Current Limit),
  // which it then holds there against the servo until the servo's goal comes
  // within 4 ticks of it (a compliant recorder follows the hand) or the
  // torque goes off or up. False, and nothing moves, against a full torque;
  // with physics the joint is the physics' (which has no torque limit).
  bool plugged() const { return plugged_; }
  void set_plugged(bool plugged, Nanos now);
  bool hand_move(std::int32_t ticks, Nanos now);
  bool yields_to_hand() const;
  int baud() const;  // the Baud Rate register in bits per second
  // Present Position (raw) at `now`, without changing the state.
  std::int32_t present_ticks(Nanos now) const;
  // How many reads this servo has answered that carried its Present
  // Position (directly or through Indirect Data): what a test's scripted
  // hand counts to move in step with a host's reads, not with a timer.
  std::uint64_t position_reads() const { return position_reads_; }

  // Fault injection: the next `answers` status packets (every one while
  // answers < 0) leave `delay_ns` of real time late, so a client sees late
  // answers as from a slow or overloaded servo. delay_ns 0 switches it off.
  void set_answer_delay(Nanos delay_ns, int answers = -1);
  // The delay for the status packet about to be sent (consumes one count).
  Nanos take_answer_delay() const;

  // Goals received so far, oldest first (at most kGoalLogCapacity; older
  // ones are dropped), and how many were received in all.
  std::vector<GoalRecord> goal_log() const;
  std::uint64_t goals_received() const { return goals_received_; }
  void clear_goal_log();

  // Current, supply and temperature (servo_health_model.hpp): Present
  // Current, Present Input Voltage, Present Temperature and the Hardware
  // Error bits they cause. Changes take effect at the next advance().
  ServoHealthModel& health() { return health_; }

  // Present position in radians through the binding, at time `now`, without
  // changing the state (with physics: where the physics is now).
  double position_rad(Nanos now) const;

 private:
  using Motor = ServoMotor;  // ticks, ticks/s
  Motor motor_at(Nanos now) const;
  Motor motor_until(Nanos now) const;  // the motor model alone, no watchdog
  Nanos watchdog_fire_time() const;    // when the armed watchdog fires; -1: not armed
  dxl::StatusError check_write(std::uint16_t address, std::span<const std::uint8_t> data) const;
  dxl::StatusError check_direct(std::uint16_t address, std::span<const std::uint8_t> data) const;
  void reset_ram();
  void latch_shutdown();
  void let_go_of_hand();    // after a write: the hand holds on only against a weak pull
  void publish(Nanos now);  // motor state -> present-value registers
  void command_physics();   // goal and torque -> physics
  std::int32_t reg32(std::uint16_t address) const;
  // The motor turns in its own ticks; Present and Goal Position are those
  // plus the Homing Offset.
  std::int32_t motor_goal() const;  // Goal Position (within the limits in mode 3), motor ticks
  std::int32_t present_of(double motor_ticks) const;
  // The turn count starts again from the shaft's angle within its turn.
  void count_from_single_turn();

  ActuatorBinding binding_;
  double tau_s_;
  double vmax_ticks_s_;
  std::array<std::uint8_t, dxl::xreg::table_size> table_{};
  ServoEeprom eeprom_{kDynamixelX};
  Motor motor_;
  // Motor ticks where the count of turns started (a multiple of a turn):
  // Present Position = motor - turn_base_ + Homing Offset.
  std::int32_t turn_base_ = 0;
  Nanos motor_time_;
  JointPhysics* physics_ = nullptr;
  int physics_joint_ = -1;
  ServoHealthModel health_;
  Nanos watchdog_fed_ = 0;  // the latest instruction packet for this servo
  bool responding_ = true;
  bool plugged_ = true;
  bool hearing_ = true;
  bool shut_down_ = false;
  bool held_by_hand_ = false;
  std::uint8_t injected_error_ = 0;
  // Reg Write waiting for Action.
  std::array<std::uint8_t, dxl::xreg::table_size> pending_{};
  std::uint16_t pending_address_ = 0;
  std::uint16_t pending_length_ = 0;
  // Fault injection and the goal log.
  Nanos answer_delay_ns_ = 0;
  mutable int delayed_answers_left_ = 0;      // < 0: every answer
  mutable std::uint64_t position_reads_ = 0;  // counted by read(), which changes no register
  std::vector<GoalRecord> goal_ring_;
  std::uint64_t goals_received_ = 0;
  void log_goal(std::uint16_t address, std::span<const std::uint8_t> data, bool accepted);
};

}  // namespace animrt::sim
