#pragma once
// Master side of a bus of MIT-mode motors. configure(): "exit motor mode" to
// each motor (nothing is energised; the reply says it is there and where it
// is). activate(): "enter motor mode", then hold the present position with
// the configured kp/kd. Each cycle write() sends one command per motor and
// collects the replies (one deadline for all); read() hands out the
// positions those replies carried. deactivate(): "exit motor mode".

#include <chrono>
#include <memory>
#include <span>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/can_transport.hpp"
#include "animrt/bridge/status_book.hpp"

namespace animrt {

class MitBus final : public ActuatorBus {
 public:
  static constexpr int kTries = 3;      // per motor, lifecycle frames only
  static constexpr int kMaxId = 0x7FF;  // 11-bit CAN identifiers

  // Throws DeviceError for ids outside 1..2047, duplicates, or an id equal
  // to the master id.
  MitBus(BusConfig config, std::unique_ptr<CanFrameTransport> transport);

  const BusConfig& config() const override { return config_; }
  void configure() override;
  void activate() override;
  // The motors' CAN timeout (device_watchdog_ms, set in their setup menu) ran
  // from activate()'s hold command: held again at the same positions, so the
  // time the other buses took to come up does not make them go limp; if it
  // already ran out they went limp and may have moved, and holding them at
  // the old positions would jump: refused (DeviceError) instead.
  void arm_device_guard() override;
  void deactivate() override;
  void read(std::span<double> positions) override;
  void write(std::span<const double> positions) override;
  std::span<DeviceStatus> devices() override { return book_.devices(); }
  // Every reply carries the torque, and an 8-byte one the temperature: both
  // go to DeviceStatus::reading at no cost to the cycle. (The error code
  // takes the fault path of DeviceStatus::hardware_error_status.)
  bool reads_health() const override { return true; }

  const CanFrameTransport& transport() const { return *transport_; }
  std::uint64_t foreign_frames() const { return foreign_frames_; }  // replies from ids not ours
  // Latest reply per motor (motor units: rad, rad/s, N m).
  const mit::Reply& last_reply(std::size_t device) const { return reply_[device]; }

 private:
  // Sends frames_[i] to every motor with pending_[i] set, then collects
  // replies until each answered or the deadline passed; returns how many
  // motors did not answer.
  std::size_t exchange();
  std::string prefix() const { return book_.prefix(); }
  std::string describe(std::size_t device) const { return book_.describe(device); }
  std::string missing_list() const;

  BusConfig config_;
  MitBusOptions bus_options_;
  std::vector<MitMotorOptions> motor_;
  Nanos held_at_ = 0;  // when activate() sent its hold command
  std::unique_ptr<CanFrameTransport> transport_;
  std::chrono::microseconds timeout_;

  StatusBook book_;
  std::vector<mit::Reply> reply_;
  std::vector<double> goal_motor_rad_;
  std::vector<can_frame> frames_;
  std::vector<std::uint8_t> pending_;
  std::vector<int> slot_of_id_;  // motor id -> device index, -1 if not ours
  std::uint64_t foreign_frames_ = 0;
  bool fresh_ = false;
};

}  // namespace animrt
