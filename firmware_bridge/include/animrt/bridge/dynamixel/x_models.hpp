#pragma once
// Dynamixel X-series models the runtime knows by name: the model number each
// reports at Control Table address 0 (and in its answer to Ping), and whether
// it takes Fast Sync Read / Fast Bulk Read. Numbers from the models' e-manual
// pages; fast read support from the Protocol 2.0 page (X430/X540 from
// firmware 45, X330 from 46; 2XL/2XC never).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "animrt/bridge/bus_config.hpp"

namespace animrt::dxl {

struct XModel {
  std::string_view name;  // as printed on the servo, e.g. "XM430-W350"
  std::uint16_t number;
  std::uint8_t fast_read_firmware;  // first firmware with fast read; 0: none
};

std::span<const XModel> x_models();
const XModel* find_x_model(std::string_view name);
const XModel* find_x_model(std::uint16_t number);
// Every known name, comma-separated (for error messages).
std::string x_model_names();

// Whether a servo reporting this model number and firmware version answers
// Fast Sync Read and Fast Bulk Read. Unknown models: no.
bool supports_fast_read(std::uint16_t model_number, std::uint8_t firmware);

// How the bus reads present positions each cycle (bus key `fast_read`).
enum class FastRead : std::uint8_t {
  automatic,  // Fast Sync Read when every servo supports it (decided at configure)
  on,         // always Fast Sync Read
  off,        // always plain Sync Read
};

// Whether and how the bus reads Present Current, Present Input Voltage,
// Present Temperature and Hardware Error Status (bus key `health`). Both
// ways map them, after Present Position, into the Indirect Data region.
enum class HealthRead : std::uint8_t {
  off,          // positions only
  packed,       // every cycle, in the same (Fast) Sync Read as the positions
  round_robin,  // one servo per cycle, in a Read of its own after the positions
};

// Present Current unit (A) of a model; 0 for models whose register 126 is
// Present Load (XL430, 2XL430, XC430, 2XC430, XL330, XC330), not current.
double current_unit_a(std::uint16_t model_number);

// Protocol-specific settings (BusConfig::options / ActuatorBinding::options).
struct BusOptions {
  HealthRead health = HealthRead::off;
  FastRead fast_read = FastRead::automatic;
  std::uint16_t model_number = 0;  // the bus's `model`, for devices without one; 0: none
  // Bus Watchdog (address 98) set at activate, in its units of 20 ms; 0: none.
  std::uint8_t bus_watchdog = 0;
};
struct DeviceOptions {
  std::uint16_t model_number = 0;  // 0: no `model` given
  // `multi_turn: true`: extended position control (Operating Mode 4), the
  // home set by the servo's Homing Offset; else position control (3).
  bool multi_turn = false;
};

// The options of a bus or device; defaults when none were stored.
BusOptions bus_options(const BusConfig& bus);
DeviceOptions device_options(const ActuatorBinding& binding);

}  // namespace animrt::dxl
