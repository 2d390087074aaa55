// A Dynamixel X servo held by a weak torque for commissioning: current-based
// position mode with a low Goal Current, so a hand moves the joint and the
// servo still holds it against little more than its weight.

#include <algorithm>
#include <cmath>
#include <string>

#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt {

bool DynamixelBus::activate_compliant(std::size_t device, double share) {
  const std::size_t n = link_.book().size();
  if (device >= n || link_.book()[device].faulted || current_unit_[device] == 0.0) return false;
  if (mode_before_.size() != n) mode_before_.assign(n, kModeKept);
  const auto id = link_.bus_id(device);
  const auto check = [&](Answer answer, const std::string& what) {
    if (answer == Answer::ok) return;
    const std::string message =
        prefix() + "cannot " + what + " of " + describe(device) + ": " + failure(device, answer);
    deactivate();
    throw DeviceError(message);
  };
  // Operating Mode is EEPROM: written with torque off, put back by deactivate().
  check(write_register(device, dxl::xreg::torque_enable, 0, 1, kTries), "turn torque off");
  check(unicast(device, dxl::encode_read(id, dxl::xreg::operating_mode, 1, link_.tx()), 1),
        "read Operating Mode");
  const auto mode = static_cast<std::uint8_t>(link_.value(0));
  if (mode != dxl::kCurrentBasedPositionMode) {
    check(write_register(device, dxl::xreg::operating_mode, dxl::kCurrentBasedPositionMode, 1,
                         kTries),
          "set Operating Mode 5 (current-based position)");
    if (mode_before_[device] == kModeKept) mode_before_[device] = mode;
  }
  check(unicast(device, dxl::encode_read(id, dxl::xreg::current_limit, 2, link_.tx()), 2),
        "read Current Limit");
  const double limit = link_.value(0) & 0xFFFF;
  const auto goal = static_cast<std::uint32_t>(
      std::clamp(std::lround(share * limit), 1L, static_cast<long>(limit)));
  check(write_register(device, dxl::xreg::goal_current, goal, 2, kTries), "write Goal Current");
  check(unicast(device, dxl::encode_read(id, dxl::xreg::present_position, 4, link_.tx()), 4),
        "read Present Position");
  const auto ticks = static_cast<std::int32_t>(link_.value(0));
  check(write_register(device, dxl::xreg::goal_position, static_cast<std::uint32_t>(ticks), 4,
                       kTries),
        "write Goal Position");
  positions_.found(device, ticks);
  check(write_register(device, dxl::xreg::torque_enable, 1, 1, kTries), "enable torque");
  return true;
}

void DynamixelBus::restore_operating_mode(std::size_t device) {
  if (device >= mode_before_.size() || mode_before_[device] == kModeKept) return;
  write_register(device, dxl::xreg::operating_mode, mode_before_[device], 1, kTries);
  mode_before_[device] = kModeKept;
}

}  // namespace animrt
