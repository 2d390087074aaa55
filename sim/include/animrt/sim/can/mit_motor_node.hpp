#pragma once
// A simulated MIT-mode motor (AK-series firmware behaviour): answers every
// frame addressed to it with its state (8-byte reply: position, velocity,
// torque, temperature, error code) to the master id. Special frames enter
// and exit motor mode and set the zero; a command frame is obeyed only in
// motor mode. With kp > 0 the rotor follows the commanded position through
// the motor model; with kp = 0 (or outside motor mode) it stays where it is.
// A fault (error code != 0) leaves motor mode until the fault is cleared.
// CAN timeout (the bus's device_watchdog_ms, as set in each motor's setup
// menu; 0: none): in motor mode, when no frame addressed to the motor came
// for longer than the timeout, the command is zeroed (kp, kd, torque): the
// motor goes limp (here: it stops where it is) and stays in motor mode; the
// next command drives it again.
// Temperature: the servos' health model (sim.health, sim.inject): a
// thermal model driven by the current the motion draws, or the stall
// current while the joint is blocked (it then stays where it is); an
// injected hardware error is the reply's error code.

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/can/can_options.hpp"
#include "animrt/sim/can/can_node.hpp"
#include "animrt/sim/can/motor_model.hpp"
#include "animrt/sim/servo_health_model.hpp"

namespace animrt::sim {

class MitMotorNode final : public CanNode {
 public:
  // can_timeout_ms: the firmware's CAN timeout (0: none).
  MitMotorNode(const ActuatorBinding& binding, canid_t master_id, const SimBusSettings& settings,
               Nanos now, int can_timeout_ms = 0);

  int device_id() const override { return binding_.device_id; }
  std::vector<canid_t> listens_to() const override;
  void handle(const can_frame& frame, Nanos now, FrameList& out) override;
  void poll(Nanos now, FrameList& out) override;
  double joint_position(Nanos now) const override;
  void set_fault(std::uint8_t bits, Nanos now, FrameList& out) override;
  void reboot(Nanos now, FrameList& out) override;
  void inject_health(const SimHealthInjection& change, Nanos now, FrameList& out) override;

  bool motor_mode() const { return motor_mode_; }
  const mit::Command& command() const { return command_; }
  // Limp after a CAN timeout (until the next command), and how often.
  bool timed_out() const { return timed_out_; }
  bool guard_fired() const override { return timed_out_; }
  std::uint64_t timeouts() const { return timeouts_; }
  double motor_position(Nanos now) const { return motor_.position(now) - zero_; }

 private:
  can_frame reply(Nanos now) const;
  void advance_health(Nanos now, FrameList& out);

  ActuatorBinding binding_;
  MitMotorOptions options_;
  canid_t master_id_;
  LagMotor motor_;
  ServoHealthModel health_;
  double zero_ = 0.0;  // rotor angle that reads as 0
  bool motor_mode_ = false;
  mit::Command command_;
  std::uint8_t error_ = 0;
  Nanos can_timeout_ = 0;  // 0: none
  Nanos last_frame_ = 0;
  bool timed_out_ = false;
  std::uint64_t timeouts_ = 0;
};

}  // namespace animrt::sim
