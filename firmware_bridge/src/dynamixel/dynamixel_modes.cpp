// The Operating Mode each joint needs, put right at configure (a process
// killed during a compliant hold leaves current-based position mode in
// EEPROM), and the home of a multi-turn joint: its Homing Offset.

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

std::string mode_text(std::uint32_t mode) {
  const char* name = mode == 0    ? "current"
                     : mode == 1  ? "velocity"
                     : mode == 3  ? "position"
                     : mode == 4  ? "extended position"
                     : mode == 5  ? "current-based position"
                     : mode == 16 ? "PWM"
                                  : "unknown";
  return std::to_string(mode) + " (" + name + ")";
}

// Homing Offset's range (+-255 turns).
constexpr std::int64_t kMaxHomingOffset = 1'044'479;
constexpr std::int64_t kTicksPerTurn = 4096;
// A servo answers again within about a second after Reboot.
constexpr auto kRestartWait = std::chrono::milliseconds(1500);
// How far the read-back may be from the home asked for (a hand's tremor).
constexpr std::int64_t kHomeSlackTicks = 2;

}  // namespace

std::uint8_t DynamixelBus::needed_mode(std::size_t device) const {
  return dxl::device_options(config_.actuators[device]).multi_turn ? dxl::kExtendedPositionMode
                                                                   : dxl::kPositionMode;
}

void DynamixelBus::set_operating_modes() {
  mode_warning_.clear();
  for (std::size_t i = 0; i < link_.book().size(); ++i) {
    const auto id = link_.bus_id(i);
    const auto fail = [&](Answer answer, const std::string& what) {
      throw DeviceError(prefix() + "cannot " + what + " of " + describe(i) + ": " +
                        failure(i, answer));
    };
    Answer r = unicast(i, dxl::encode_read(id, dxl::xreg::operating_mode, 1, link_.tx()), 1);
    if (r != Answer::ok) fail(r, "read Operating Mode");
    const std::uint32_t have = link_.value(0);
    const std::uint8_t want = needed_mode(i);
    if (have == want) continue;
    // EEPROM: written with torque off.
    r = write_register(i, dxl::xreg::torque_enable, 0, 1, kTries);
    if (r != Answer::ok) fail(r, "turn torque off to set the Operating Mode");
    r = write_register(i, dxl::xreg::operating_mode, want, 1, kTries);
    if (r != Answer::ok) fail(r, "set Operating Mode " + mode_text(want));
    const std::string line =
        describe(i) + " was in Operating Mode " + mode_text(have) + ", set to " + mode_text(want);
    mode_warning_ += (mode_warning_.empty() ? "" : "; ") + line;
    std::fprintf(stderr, "warning: bus %s: %s\n", config_.name.c_str(), line.c_str());
  }
}

void DynamixelBus::reboot_and_wait(std::size_t device) {
  const auto id = link_.bus_id(device);
  const Answer r = unicast(device, dxl::encode_packet(id, dxl::inst::reboot, {}, link_.tx()), 0);
  if (r != Answer::ok) {
    throw DeviceError(prefix() + "cannot reboot " + describe(device) + ": " + failure(device, r));
  }
  const auto end = std::chrono::steady_clock::now() + kRestartWait;
  for (;;) {
    if (unicast(device, dxl::encode_ping(id, link_.tx()), servo::kAnyLength, 1) == Answer::ok) {
      break;
    }
    if (std::chrono::steady_clock::now() > end) {
      throw DeviceError(prefix() + describe(device) + ": no answer after Reboot");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  // RAM is at its defaults again: the health registers' map is gone.
  if (health_ != dxl::HealthRead::off) map_health_registers(device);
}

std::int64_t DynamixelBus::set_home(std::size_t device, std::int64_t ticks) {
  if (device >= link_.book().size()) return ActuatorBus::set_home(device, ticks);
  if (!dxl::device_options(config_.actuators[device]).multi_turn) {
    throw DeviceError(prefix() + describe(device) +
                      ": not multi_turn; its home is the robot file's zero_ticks");
  }
  const auto id = link_.bus_id(device);
  const auto fail = [&](Answer answer, const std::string& what) {
    throw DeviceError(prefix() + "cannot " + what + " of " + describe(device) + ": " +
                      failure(device, answer));
  };
  const auto read32 = [&](std::uint16_t address, const std::string& what) {
    const Answer r = unicast(device, dxl::encode_read(id, address, 4, link_.tx()), 4);
    if (r != Answer::ok) fail(r, "read " + what);
    return static_cast<std::int64_t>(static_cast<std::int32_t>(link_.value(0)));
  };
  Answer r = write_register(device, dxl::xreg::torque_enable, 0, 1, kTries);
  if (r != Answer::ok) fail(r, "turn torque off");
  const std::int64_t count = read32(dxl::xreg::present_position, "Present Position") -
                             read32(dxl::xreg::homing_offset, "Homing Offset");
  // A power-up counts from the shaft's angle within its turn: the offset is
  // taken from that angle, so the home reads the same after a power cycle.
  const std::int64_t angle = ((count % kTicksPerTurn) + kTicksPerTurn) % kTicksPerTurn;
  const std::int64_t offset = ticks - angle;
  if (offset < -kMaxHomingOffset || offset > kMaxHomingOffset) {
    throw DeviceError(prefix() + describe(device) + ": Homing Offset " + std::to_string(offset) +
                      " is outside +-" + std::to_string(kMaxHomingOffset) +
                      "; give the joint a zero_ticks nearer 0");
  }
  r = write_register(device, dxl::xreg::homing_offset, static_cast<std::uint32_t>(offset), 4,
                     kTries);
  if (r != Answer::ok) fail(r, "write Homing Offset " + std::to_string(offset));
  if (read32(dxl::xreg::homing_offset, "Homing Offset") != offset) {
    throw DeviceError(prefix() + describe(device) + ": Homing Offset did not keep " +
                      std::to_string(offset));
  }
  // As at a power-up: the count starts again from the shaft's angle.
  reboot_and_wait(device);
  const std::int64_t present = read32(dxl::xreg::present_position, "Present Position");
  if (present < ticks - kHomeSlackTicks || present > ticks + kHomeSlackTicks) {
    throw DeviceError(prefix() + describe(device) + ": homed to read " + std::to_string(ticks) +
                      ", reads " + std::to_string(present) + " after Reboot");
  }
  positions_.found(device, static_cast<std::int32_t>(present));
  return present;
}

}  // namespace animrt
