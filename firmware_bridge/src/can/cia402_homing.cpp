// Homing a CiA 402 drive for commissioning: on its current position
// (methods 37 / 35), the drive's own zero where the joint rests, or by a
// search for a limit or home switch (methods 17-30), which moves the joint.

#include <chrono>
#include <cstdlib>
#include <limits>
#include <string>
#include <thread>

#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

// SYNC cycles a homing on the current position may take.
constexpr int kHomingCycles = 20;
// A switch search is watched at this pace, until its homing timeout.
constexpr auto kSearchPace = std::chrono::milliseconds(5);
// How far the read-back may be from the home asked for.
constexpr std::int64_t kHomeSlackCounts = 2;

std::string hex16(std::uint16_t v) {
  static const char* digits = "0123456789ABCDEF";
  std::string s = "0x";
  for (int shift = 12; shift >= 0; shift -= 4) s += digits[(v >> shift) & 0xF];
  return s;
}

}  // namespace

std::string Cia402Bus::run_homing(std::size_t device) {
  using namespace cia402;
  const std::string stuck = walk_to(State::operation_enabled, device);
  if (!stuck.empty()) return "cannot enable operation: " + stuck;
  const Cia402Homing& homing = joint_options_[device].homing;
  // A search moves the joint for as long as it takes (bus time, and wall
  // time where the bus's clock is a simulation's); on the spot, a few SYNCs.
  const Nanos bus_start = transport_->now();
  const auto wall_start = std::chrono::steady_clock::now();
  const auto limit = std::chrono::duration<double>(homing.timeout_s);
  const auto over = [&](int k) {
    if (!homing.on_switches()) return k >= kHomingCycles;
    return to_seconds(transport_->now() - bus_start) > homing.timeout_s ||
           std::chrono::steady_clock::now() - wall_start > limit;
  };
  const std::uint16_t done = kSwHomingAttained | kSwTargetReached;
  std::string failure =
      homing.on_switches()
          ? "no homing attained within " + format_number(homing.timeout_s) +
                " s (timeout_s): the switch was not found"
          : "no homing attained after " + std::to_string(kHomingCycles) + " cycles";
  for (int k = 0; !over(k); ++k) {
    // Bit 4 low first, then high: the homing starts on its rising edge.
    const std::uint16_t start = k == 0 ? 0 : kCwHomingStart;
    send_rpdo(device, cw::enable_operation | start, actual_counts_[device]);
    sync_cycle();
    const std::uint16_t sw = drive_[device].statusword;
    if (k == 0) continue;
    if (sw & kSwHomingError) {
      failure = "homing error (statusword " + hex16(sw) + ")";
      if (homing.on_switches()) {
        failure += ": method " + std::to_string(homing.method) +
                   " met a limit switch it does not use, or did not find its switch";
      }
      break;
    }
    if ((sw & done) == done) {
      failure.clear();
      break;
    }
    if (homing.on_switches()) std::this_thread::sleep_for(kSearchPace);
  }
  // Bit 4 low: a search still running is interrupted (the drive stops).
  send_rpdo(device, cw::enable_operation, actual_counts_[device]);
  sync_cycle();
  return failure;
}

void Cia402Bus::write_homing_method(std::size_t device) {
  using namespace cia402;
  const Cia402Homing& homing = joint_options_[device].homing;
  if (homing.method == kHomingHere) {
    try {
      sdo_write(device, obj::homing_method, 0, static_cast<std::uint8_t>(kHomingHere), 1);
    } catch (const DeviceError&) {
      // A drive of the older profile knows homing on the current position as 35.
      sdo_write(device, obj::homing_method, 0, static_cast<std::uint8_t>(kHomingHereOld), 1);
    }
    return;
  }
  sdo_write(device, obj::homing_method, 0, static_cast<std::uint8_t>(homing.method), 1);
  if (!homing.on_switches()) return;
  sdo_write(device, obj::homing_speeds, 1, homing.switch_speed, 4);
  sdo_write(device, obj::homing_speeds, 2, homing.zero_speed, 4);
  if (homing.acceleration != 0) {
    sdo_write(device, obj::homing_accel, 0, homing.acceleration, 4);
  }
}

std::int64_t Cia402Bus::set_home(std::size_t device, std::int64_t ticks) {
  if (device >= book_.size()) return ActuatorBus::set_home(device, ticks);
  if (running_) throw DeviceError(prefix() + describe(device) + ": not homed while the bus runs");
  if (ticks < std::numeric_limits<std::int32_t>::min() ||
      ticks > std::numeric_limits<std::int32_t>::max()) {
    throw DeviceError(prefix() + describe(device) + ": home offset " + std::to_string(ticks) +
                      " does not fit 607Ch (32 bits)");
  }
  using namespace cia402;
  write_homing_method(device);
  sdo_write(device, obj::home_offset, 0, static_cast<std::uint32_t>(ticks), 4);
  sdo_write(device, obj::modes_of_operation, 0, static_cast<std::uint8_t>(kModeHoming), 1);
  // PDOs and SYNC need the node operational; it goes back to pre-operational after.
  nmt(canopen::NmtCommand::start, device);
  std::string failure;
  try {
    // Enabled, the drive watches the host as in a run: a host that dies
    // mid-search stops it within device_watchdog_ms, not at its switches.
    arm_guard(device);
    failure = run_homing(device);
  } catch (const DeviceError& e) {
    failure = e.what();
  }
  walk_to(State::switch_on_disabled, device);
  clear_device_guard(device);
  nmt(canopen::NmtCommand::enter_pre_operational, device);
  sdo_write(device, obj::modes_of_operation, 0, static_cast<std::uint8_t>(kModeCsp), 1);
  if (!failure.empty()) {
    throw DeviceError(prefix() + "cannot home " + describe(device) + ": " + failure);
  }
  const auto reads = static_cast<std::int32_t>(sdo_read(device, obj::position_actual, 0));
  actual_counts_[device] = reads;
  target_counts_[device] = reads;
  // After a search the drive stops past the edge by its braking distance.
  if (!joint_options_[device].homing.on_switches() &&
      std::llabs(reads - ticks) > kHomeSlackCounts) {
    throw DeviceError(prefix() + describe(device) + ": homed to read " + std::to_string(ticks) +
                      ", reads " + std::to_string(reads));
  }
  return reads;
}

}  // namespace animrt
