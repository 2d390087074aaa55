#pragma once
// MIT mini-cheetah motor mode (T-Motor / CubeMars AK series and the many
// motors that copied it), used by both ends of the wire: the runtime's bus
// driver and the simulated motor.
//
// Command, standard frame to the motor's id, 8 bytes, big-endian bit fields:
//   position 16 bits | velocity 12 | kp 12 | kd 12 | torque 12
// each linear over a per-model range [min, max] (integer = (x - min) *
// (2^bits - 1) / (max - min), truncated, as in the vendor's float_to_uint).
// Reply, standard frame to the master id, 6 bytes (8 on newer firmware):
//   motor id 8 | position 16 | velocity 12 | torque 12 [| temperature 8 | error 8]
// Special frames: FF FF FF FF FF FF FF then FC (enter motor mode), FD (exit
// motor mode), FE (set the present position as zero).
// Sources: CubeMars "AK Series Actuator Driver Manual" v1.0.8, section 5.3
// (frame layout, special frames, per-model ranges, pack/unpack routines).

#include <linux/can.h>

#include <cstdint>
#include <string>
#include <string_view>

namespace animrt::mit {

// The firmware's current loop rate. Its CAN timeout (setup menu, 0: none)
// counts these cycles in motor mode since the last frame addressed to the
// motor; past it the commands are zeroed (kp, kd, torque): the motor goes
// limp and stays in motor mode until the next command.
inline constexpr int kCurrentLoopHz = 40'000;

struct Ranges {
  double p_min = -12.5, p_max = 12.5;   // rad
  double v_min = -50.0, v_max = 50.0;   // rad/s
  double kp_min = 0.0, kp_max = 500.0;  // N m / rad
  double kd_min = 0.0, kd_max = 5.0;    // N m s / rad
  double t_min = -18.0, t_max = 18.0;   // N m
};

// Ranges of a named model ("ak80-9", ...) as printed in the manual; nullptr
// for an unknown name.
const Ranges* find_model(std::string_view model);
std::string supported_models();  // "ak10-9, ak60-6, ..."

struct Command {
  double position = 0, velocity = 0, kp = 0, kd = 0, torque = 0;
};

struct Reply {
  std::uint8_t motor_id = 0;
  double position = 0, velocity = 0, torque = 0;
  bool extended = false;  // 8-byte reply: temperature and error code follow
  std::uint8_t temperature = 0;
  std::uint8_t error = 0;  // 0 = no fault
};

enum class Special : std::uint8_t { none, enter_motor_mode, exit_motor_mode, set_zero };

// Fixed-point conversions (x clamped into [min, max]).
std::uint32_t float_to_uint(double x, double min, double max, int bits);
double uint_to_float(std::uint32_t value, double min, double max, int bits);

// Values outside the ranges are clamped (the caller enforces its own, tighter
// limits before this). Never allocates.
can_frame pack_command(canid_t motor_id, const Command& command, const Ranges& ranges);
// False for a frame that is not an 8-byte command (or is a special frame).
bool unpack_command(const can_frame& frame, const Ranges& ranges, Command& out);

can_frame pack_reply(canid_t master_id, const Reply& reply, const Ranges& ranges);
// False unless 6 or 8 data bytes.
bool unpack_reply(const can_frame& frame, const Ranges& ranges, Reply& out);

can_frame special_frame(canid_t motor_id, Special which);
Special special_of(const can_frame& frame);

}  // namespace animrt::mit
