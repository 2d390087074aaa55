// A Feetech STS servo held by a weak torque for commissioning: its Torque
// Limit lowered, so a hand moves the joint and the servo still holds it
// against little more than its weight.

#include <algorithm>
#include <cmath>
#include <string>

#include "animrt/bridge/feetech/feetech_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt {

FeetechBus::Answer FeetechBus::write_torque_limit(std::size_t device, std::uint16_t limit) {
  std::uint8_t data[2];
  ft::put_u16(series_, data, limit);
  const std::uint8_t id = link_.bus_id(device);
  return unicast(device, ft::encode_write(id, ft::reg::sts_torque_limit, data, link_.tx()), 0);
}

bool FeetechBus::activate_compliant(std::size_t device, double share) {
  const std::size_t n = link_.book().size();
  if (series_ != ft::Series::sts || device >= n || link_.book()[device].faulted) return false;
  if (limit_before_.size() != n) limit_before_.assign(n, 0);
  const auto id = link_.bus_id(device);
  const auto check = [&](Answer answer, const std::string& what) {
    if (answer == Answer::ok) return;
    const std::string message =
        prefix() + "cannot " + what + " of " + describe(device) + ": " + failure(device, answer);
    deactivate();
    throw DeviceError(message);
  };
  check(write_byte(device, ft::reg::torque_enable, 0), "turn torque off");
  check(unicast(device, ft::encode_read(id, ft::reg::sts_torque_limit, 2, link_.tx()), 2),
        "read Torque Limit");
  // Torque Limit is RAM: put back by deactivate(), or by the next power-up.
  if (limit_before_[device] == 0)
    limit_before_[device] = static_cast<std::uint16_t>(link_.value(0));
  const auto limit = static_cast<std::uint16_t>(std::clamp(
      std::lround(share * ft::kStsFullTorque), 1L, static_cast<long>(ft::kStsFullTorque)));
  check(write_torque_limit(device, limit), "write Torque Limit");
  check(unicast(device, ft::encode_read(id, ft::reg::present_position, 2, link_.tx()), 2),
        "read Present Position");
  const std::int32_t ticks = to_position(static_cast<std::uint16_t>(link_.value(0)));
  check(write_goal(device, ticks), "write Goal Position");
  positions_.found(device, ticks);
  check(write_byte(device, ft::reg::torque_enable, 1), "enable torque");
  return true;
}

}  // namespace animrt
