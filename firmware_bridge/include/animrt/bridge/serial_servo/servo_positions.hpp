#pragma once
// What a serial-servo bus keeps per servo in position mode, the same for
// every family: the latest measured position, the latest goal sent, and
// the goals allowed now (GoalWindow), in the servo's ticks. configure()
// fills it from the servos, read() hands the measured positions out in
// radians, write() turns goals in radians into ticks. No allocation after
// init().

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/goal_window.hpp"
#include "animrt/bridge/status_book.hpp"

namespace animrt::servo {

class ServoPositions {
 public:
  // Every servo at its binding's zero; goals inside the joint's limits and
  // the servo's range [min_ticks, max_ticks].
  void init(const BusConfig& config, std::int32_t min_ticks, std::int32_t max_ticks);

  std::int32_t present(std::size_t device) const { return present_[device]; }
  std::int32_t goal(std::size_t device) const { return goal_[device]; }

  // configure(): from its start until ready(), read() hands out nothing.
  void forget_found() { fresh_ = false; }
  void ready() { fresh_ = true; }
  // configure(): the position read from the servo; its goal is where it is.
  void found(std::size_t device, std::int32_t ticks) { present_[device] = goal_[device] = ticks; }
  // configure(), after every position was found: each window starts where
  // its joint rests. Returns the warning about the joints resting outside
  // their limits (also printed to stderr), empty when none does.
  // `limits_name`: the servo's name for its limit registers.
  std::string start(const StatusBook& book, const char* limits_name);

  // configure(): what a servo's own position limits should hold for a joint
  // with limits: the joint's limits in ticks, widened to where the joint
  // rests if it rests outside them (else the servo would refuse to hold it,
  // or torque on would snap it to a limit), inside 0..top.
  struct Span {
    std::int32_t lo, hi;
  };
  Span limit_ticks(std::size_t device, std::int32_t top) const;

  // read(): the first call after ready() hands out every found position,
  // so no entry starts undefined; then measured() updates one.
  void hand_out_found(std::span<double> positions);
  void measured(std::size_t device, std::int32_t ticks, std::span<double> positions);

  // write(): the goal of `device` for `rad` (clamped into its window; a NaN
  // or infinite goal holds the last one), remembered as sent.
  std::int32_t take_goal(std::size_t device, double rad);

 private:
  std::string bus_;
  std::vector<ActuatorBinding> bindings_;
  std::vector<std::int32_t> present_;
  std::vector<std::int32_t> goal_;
  std::vector<GoalWindow> window_;
  bool fresh_ = false;  // found positions not yet handed out
};

}  // namespace animrt::servo
