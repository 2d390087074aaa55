#pragma once
// A simulated MIT-mode motor (AK-series firmware behaviour): answers every
// frame addressed to it with its state (8-byte reply: position, velocity,
// torque, temperature, error code) to the master id. Special frames enter
// and exit motor mode and set the zero; a command frame is obeyed only in
// motor mode. With kp > 0 the rotor follows the commanded position through
// the motor model; with kp = 0 (or outside motor mode) it stays where it is.
// A fault (error code != 0) leaves motor mode until the fault is cleared.

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/can/can_options.hpp"
#include "animrt/sim/can/can_node.hpp"
#include "animrt/sim/can/motor_model.hpp"

namespace animrt::sim {

class MitMotorNode final : public CanNode {
 public:
  MitMotorNode(const ActuatorBinding& binding, canid_t master_id, const SimBusSettings& settings,
               Nanos now);

  int device_id() const override { return binding_.device_id; }
  std::vector<canid_t> listens_to() const override;
  void handle(const can_frame& frame, Nanos now, FrameList& out) override;
  void poll(Nanos, FrameList&) override {}
  double joint_position(Nanos now) const override;
  void set_fault(std::uint8_t bits, Nanos now, FrameList& out) override;
  void reboot(Nanos now, FrameList& out) override;

  bool motor_mode() const { return motor_mode_; }
  const mit::Command& command() const { return command_; }
  double motor_position(Nanos now) const { return motor_.position(now) - zero_; }

 private:
  can_frame reply(Nanos now) const;

  ActuatorBinding binding_;
  MitMotorOptions options_;
  canid_t master_id_;
  LagMotor motor_;
  double zero_ = 0.0;  // rotor angle that reads as 0
  bool motor_mode_ = false;
  mit::Command command_;
  std::uint8_t error_ = 0;
};

}  // namespace animrt::sim
