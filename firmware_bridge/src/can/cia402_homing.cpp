// Homing a CiA 402 drive on its current position (methods 37 / 35), for
// commissioning: the drive's own zero where the joint rests.

#include <cstdlib>
#include <limits>
#include <string>

#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

// SYNC cycles a homing on the current position may take.
constexpr int kHomingCycles = 20;
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
  const std::uint16_t done = kSwHomingAttained | kSwTargetReached;
  std::string failure = "no homing attained after " + std::to_string(kHomingCycles) + " cycles";
  for (int k = 0; k < kHomingCycles; ++k) {
    // Bit 4 low first, then high: the homing starts on its rising edge.
    const std::uint16_t start = k == 0 ? 0 : kCwHomingStart;
    send_rpdo(device, cw::enable_operation | start, actual_counts_[device]);
    sync_cycle();
    const std::uint16_t sw = drive_[device].statusword;
    if (k == 0) continue;
    if (sw & kSwHomingError) {
      failure = "homing error (statusword " + hex16(sw) + ")";
      break;
    }
    if ((sw & done) == done) {
      failure.clear();
      break;
    }
  }
  send_rpdo(device, cw::enable_operation, actual_counts_[device]);
  sync_cycle();
  return failure;
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
  try {
    sdo_write(device, obj::homing_method, 0, static_cast<std::uint8_t>(kHomingHere), 1);
  } catch (const DeviceError&) {
    // A drive of the older profile knows homing on the current position as 35.
    sdo_write(device, obj::homing_method, 0, static_cast<std::uint8_t>(kHomingHereOld), 1);
  }
  sdo_write(device, obj::home_offset, 0, static_cast<std::uint32_t>(ticks), 4);
  sdo_write(device, obj::modes_of_operation, 0, static_cast<std::uint8_t>(kModeHoming), 1);
  // PDOs and SYNC need the node operational; it goes back to pre-operational after.
  nmt(canopen::NmtCommand::start, device);
  std::string failure;
  try {
    failure = run_homing(device);
  } catch (const DeviceError& e) {
    failure = e.what();
  }
  walk_to(State::switch_on_disabled, device);
  nmt(canopen::NmtCommand::enter_pre_operational, device);
  sdo_write(device, obj::modes_of_operation, 0, static_cast<std::uint8_t>(kModeCsp), 1);
  if (!failure.empty()) {
    throw DeviceError(prefix() + "cannot home " + describe(device) + ": " + failure);
  }
  const auto reads = static_cast<std::int32_t>(sdo_read(device, obj::position_actual, 0));
  actual_counts_[device] = reads;
  target_counts_[device] = reads;
  if (std::llabs(reads - ticks) > kHomeSlackCounts) {
    throw DeviceError(prefix() + describe(device) + ": homed to read " + std::to_string(ticks) +
                      ", reads " + std::to_string(reads));
  }
  return reads;
}

}  // namespace animrt
