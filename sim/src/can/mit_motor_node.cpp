#include "animrt/sim/can/mit_motor_node.hpp"

#include <algorithm>
#include <cmath>

#include "animrt/sim/dynamixel_servo.hpp"  // initial_offset_rad

namespace animrt::sim {
MitMotorNode::MitMotorNode(const ActuatorBinding& binding, canid_t master_id,
                           const SimBusSettings& settings, Nanos now, int can_timeout_ms)
    : binding_(binding),
      options_(options_of<MitMotorOptions>(binding.options)),
      master_id_(master_id),
      motor_(0.0, settings.time_constant_s, settings.max_speed_rad_s, now),
      health_(settings.health, binding.device_id, now),
      can_timeout_(static_cast<Nanos>(std::max(0, can_timeout_ms)) * 1'000'000),
      last_frame_(now) {
  // Start a little away from the home pose, so the start ramp has work to do.
  const double start = options_.to_motor(initial_offset_rad(binding.device_id), binding.direction);
  motor_ = LagMotor(start, settings.time_constant_s, settings.max_speed_rad_s, now);
}

std::vector<canid_t> MitMotorNode::listens_to() const {
  return {static_cast<canid_t>(binding_.device_id)};
}

double MitMotorNode::joint_position(Nanos now) const {
  return options_.to_joint(motor_position(now), binding_.direction);
}

can_frame MitMotorNode::reply(Nanos now) const {
  mit::Reply r;
  r.motor_id = static_cast<std::uint8_t>(binding_.device_id);
  r.position = motor_position(now);
  r.velocity = motor_.velocity(now);
  r.torque = 0.0;
  if (motor_mode_) {
    r.torque = command_.kp * (command_.position - r.position) +
               command_.kd * (command_.velocity - r.velocity) + command_.torque;
  }
  r.extended = true;
  r.temperature =
      static_cast<std::uint8_t>(std::clamp(std::lround(health_.temperature_c()), 0L, 255L));
  r.error = error_;
  return mit::pack_reply(master_id_, r, options_.ranges);
}

void MitMotorNode::poll(Nanos now, FrameList&) {
  if (!motor_mode_ || can_timeout_ == 0 || timed_out_) return;
  if (now - last_frame_ <= can_timeout_) return;
  timed_out_ = true;
  ++timeouts_;
  command_ = mit::Command{};  // kp = kd = torque = 0
  motor_.hold(now);
}

void MitMotorNode::handle(const can_frame& frame, Nanos now, FrameList& out) {
  if (!responding()) return;
  if ((frame.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) != 0) return;
  if ((frame.can_id & CAN_SFF_MASK) != static_cast<canid_t>(binding_.device_id)) return;
  poll(now, out);  // the loop ran out the timeout before this frame came
  advance_health(now, out);
  // Any frame addressed to the motor restarts the count; the zeroed command
  // stays until a command frame sets a new one.
  last_frame_ = now;
  if (frame.len != 8) return;  // the firmware ignores anything but 8 bytes
  switch (mit::special_of(frame)) {
    case mit::Special::enter_motor_mode:
      if (error_ == 0) {
        motor_mode_ = true;
        timed_out_ = false;
        command_ = mit::Command{};  // limp until the first command
        motor_.hold(now);
      }
      break;
    case mit::Special::exit_motor_mode:
      motor_mode_ = false;
      motor_.hold(now);
      break;
    case mit::Special::set_zero:
      motor_.hold(now);
      zero_ = motor_.position(now);
      break;
    case mit::Special::none: {
      mit::Command c;
      if (!mit::unpack_command(frame, options_.ranges, c)) return;
      if (motor_mode_) {
        command_ = c;
        timed_out_ = false;
        if (c.kp > 0.0 && !health_.blocked()) {
          motor_.set_goal(c.position + zero_, now);
        } else {
          motor_.hold(now);
        }
      }
      break;
    }
  }
  out.push_back(reply(now));
}

void MitMotorNode::set_fault(std::uint8_t bits, Nanos now, FrameList&) {
  error_ = bits;
  if (bits != 0) {
    motor_mode_ = false;
    motor_.hold(now);
  }
}

void MitMotorNode::advance_health(Nanos now, FrameList& out) {
  const bool was_blocked = health_.blocked();
  health_.advance(now, motor_.velocity(now), motor_mode_);
  if (health_.blocked() && !was_blocked) motor_.hold(now);
  if (health_.injected_bits() != 0 && error_ == 0) set_fault(health_.injected_bits(), now, out);
}

void MitMotorNode::inject_health(const SimHealthInjection& change, Nanos now, FrameList& out) {
  advance_health(now, out);
  using Kind = SimHealthInjection::Kind;
  switch (change.kind) {
    case Kind::temperature:
      health_.set_temperature(change.value);
      break;
    case Kind::blocked:
      health_.set_blocked(change.value != 0.0);
      if (health_.blocked()) motor_.hold(now);
      break;
    case Kind::supply:
      health_.set_supply(change.value);
      break;
    case Kind::hardware_error:
      set_fault(static_cast<std::uint8_t>(change.value), now, out);
      break;
  }
}

void MitMotorNode::reboot(Nanos now, FrameList&) {
  motor_mode_ = false;
  command_ = mit::Command{};
  zero_ = 0.0;
  motor_.hold(now);
}

}  // namespace animrt::sim
