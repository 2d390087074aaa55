#include "animrt/bridge/can/mit_bus.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "animrt/core/error.hpp"

namespace animrt {
MitBus::MitBus(BusConfig config, std::unique_ptr<CanFrameTransport> transport)
    : config_(std::move(config)),
      bus_options_(options_of<MitBusOptions>(config_.options)),
      transport_(std::move(transport)),
      timeout_(std::chrono::ceil<std::chrono::microseconds>(
          std::chrono::duration<double>(config_.timeout_s))) {
  const std::string bus = "bus " + config_.name + ": ";
  if (!transport_) throw DeviceError(bus + "no transport");
  const std::size_t n = config_.actuators.size();
  slot_of_id_.assign(kMaxId + 1, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    const std::string who = "motor id " + std::to_string(b.device_id) + " (" + b.joint + ")";
    if (b.device_id < 1 || b.device_id > kMaxId)
      throw DeviceError(bus + who + " is outside 1..2047");
    if (static_cast<canid_t>(b.device_id) == bus_options_.master_id) {
      throw DeviceError(bus + who + " is the master id");
    }
    if (slot_of_id_[b.device_id] >= 0) throw DeviceError(bus + who + " is used twice");
    slot_of_id_[b.device_id] = static_cast<int>(i);
    motor_.push_back(options_of<MitMotorOptions>(b.options));
  }
  book_ = StatusBook(config_, transport_->interface(), "motor id");
  reply_.resize(n);
  goal_motor_rad_.resize(n);
  frames_.resize(n);
  pending_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    goal_motor_rad_[i] = motor_[i].zero_rad;
  }
}

std::string MitBus::missing_list() const {
  return book_.list([&](std::size_t i) { return pending_[i] != 0; });
}

std::size_t MitBus::exchange() {
  std::size_t waiting = 0;
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    if (!pending_[i]) continue;
    book_.asked(i);
    transport_->send(frames_[i]);
    ++waiting;
  }
  const auto deadline = std::chrono::steady_clock::now() + timeout_;
  can_frame frame;
  mit::Reply reply;
  // Past the deadline at most this many more frames: a flood cannot hold the cycle.
  std::size_t budget = 64 + 8 * pending_.size();
  while (waiting > 0) {
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 && budget-- == 0) break;
    if (!transport_->receive(frame, std::max(left, std::chrono::microseconds(0)))) break;
    if ((frame.can_id & CAN_SFF_MASK) != bus_options_.master_id) continue;
    const int slot = frame.len >= 1 ? slot_of_id_[frame.data[0]] : -1;
    if (slot < 0) {
      ++foreign_frames_;  // another motor on a shared interface, or an NMT frame
      continue;
    }
    const auto device = static_cast<std::size_t>(slot);
    if (!mit::unpack_reply(frame, motor_[device].ranges, reply)) {
      book_.garbled(device);
      continue;
    }
    reply_[device] = reply;
    HealthReading& h = book_[device].reading;
    h.torque_nm = std::abs(reply.torque);
    h.temperature_c =
        reply.extended ? static_cast<double>(reply.temperature) : HealthReading::kNone;
    h.read_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::steady_clock::now().time_since_epoch())
                    .count();
    ++h.reads;
    if (reply.error != 0) {
      book_.hardware_fault(device, reply.error);
      book_[device].last_error_byte = reply.error;
    } else {
      book_.answered(device);
    }
    if (pending_[slot]) {
      pending_[slot] = 0;
      --waiting;
    }
  }
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    if (!pending_[i]) continue;
    book_.timed_out(i);
  }
  return waiting;
}

void MitBus::configure() {
  const canid_t flags = CAN_EFF_FLAG | CAN_RTR_FLAG;
  const can_filter filters[] = {{bus_options_.master_id, CAN_SFF_MASK | flags}};
  transport_->set_filters(filters);
  book_.reset();
  // Exit motor mode: de-energised, and every motor answers with its state.
  std::fill(pending_.begin(), pending_.end(), 1);
  for (int t = 0; t < kTries; ++t) {
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      frames_[i] = mit::special_frame(static_cast<canid_t>(config_.actuators[i].device_id),
                                      mit::Special::exit_motor_mode);
    }
    if (exchange() == 0) break;
  }
  if (std::any_of(pending_.begin(), pending_.end(), [](std::uint8_t p) { return p != 0; })) {
    std::string message = prefix() + "no answer to exit motor mode from " + missing_list();
    if (transport_->bus_off()) message += " (the interface is bus-off)";
    throw DeviceError(message);
  }
  std::string faulty;
  for (std::size_t i = 0; i < book_.size(); ++i) {
    goal_motor_rad_[i] = reply_[i].position;
    if (reply_[i].error != 0) {
      faulty += (faulty.empty() ? "" : ", ") + describe(i) + " reports error code " +
                std::to_string(reply_[i].error);
    }
  }
  if (!faulty.empty()) throw DeviceError(prefix() + faulty);
  fresh_ = true;
}

void MitBus::activate() {
  // Enter motor mode, then hold where each motor is.
  for (int step = 0; step < 2; ++step) {
    for (std::size_t i = 0; i < book_.size(); ++i) {
      pending_[i] = book_[i].faulted ? 0 : 1;
      const auto id = static_cast<canid_t>(config_.actuators[i].device_id);
      if (step == 0) {
        frames_[i] = mit::special_frame(id, mit::Special::enter_motor_mode);
      } else {
        goal_motor_rad_[i] =
            std::clamp(reply_[i].position, motor_[i].min_motor_rad, motor_[i].max_motor_rad);
        frames_[i] = mit::pack_command(
            id, {goal_motor_rad_[i], 0.0, motor_[i].kp, motor_[i].kd, 0.0}, motor_[i].ranges);
      }
    }
    for (int t = 0; t < kTries && exchange() > 0; ++t) {
    }
    held_at_ = transport_->now();
    std::string failed = missing_list();
    for (std::size_t i = 0; i < book_.size(); ++i) {
      if (!pending_[i] && !book_[i].faulted && book_[i].health == DeviceHealth::hardware_error) {
        failed += (failed.empty() ? "" : ", ") + describe(i) + " (error code " +
                  std::to_string(book_[i].hardware_error_status) + ")";
      }
    }
    if (!failed.empty()) {
      deactivate();
      throw DeviceError(prefix() + "cannot " + (step == 0 ? "enter motor mode" : "hold position") +
                        " on " + failed);
    }
  }
}

void MitBus::arm_device_guard() {
  const int timeout_ms = bus_options_.device_watchdog_ms;
  if (timeout_ms <= 0) return;
  const Nanos since_hold = transport_->now() - held_at_;
  if (since_hold >= Nanos{timeout_ms} * 1'000'000) {
    deactivate();
    throw DeviceError(prefix() + "the motors' CAN timeout (" + std::to_string(timeout_ms) +
                      " ms) ran out while the other buses came up (" +
                      std::to_string(since_hold / 1'000'000) +
                      " ms): set a longer one on the motors and in device_watchdog_ms");
  }
  for (std::size_t i = 0; i < book_.size(); ++i) pending_[i] = book_[i].faulted ? 0 : 1;
  for (int t = 0; t < kTries && exchange() > 0; ++t) {
  }
}

void MitBus::deactivate() {
  try {
    for (std::size_t i = 0; i < book_.size(); ++i) {
      pending_[i] = 1;
      frames_[i] = mit::special_frame(static_cast<canid_t>(config_.actuators[i].device_id),
                                      mit::Special::exit_motor_mode);
    }
    exchange();
    const std::string errors = describe_errors(transport_->errors());
    if (!errors.empty())
      std::fprintf(stderr, "%sCAN errors: %s\n", prefix().c_str(), errors.c_str());
  } catch (...) {
    // deactivate never throws
  }
}

void MitBus::read(std::span<double> positions) {
  const std::size_t n = std::min(positions.size(), book_.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (fresh_ || book_[i].health != DeviceHealth::timeout) {
      positions[i] = motor_[i].to_joint(reply_[i].position, config_.actuators[i].direction);
    }
  }
  fresh_ = false;
}

void MitBus::write(std::span<const double> positions) {
  for (std::size_t i = 0; i < book_.size(); ++i) {
    pending_[i] = 0;
    if (book_[i].faulted) continue;
    const MitMotorOptions& m = motor_[i];
    if (i < positions.size() && std::isfinite(positions[i])) {
      const double goal = config_.actuators[i].safe_goal(positions[i], positions[i]);
      const double motor = m.to_motor(goal, config_.actuators[i].direction);
      goal_motor_rad_[i] = std::clamp(motor, m.min_motor_rad, m.max_motor_rad);
    }
    frames_[i] = mit::pack_command(static_cast<canid_t>(config_.actuators[i].device_id),
                                   {goal_motor_rad_[i], 0.0, m.kp, m.kd, 0.0}, m.ranges);
    pending_[i] = 1;
  }
  exchange();
}

}  // namespace animrt
