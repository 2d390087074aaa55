#pragma once
// What a bus scan found: the devices that answered safe queries (nothing
// moves, torque is never switched on), and the ids where several devices
// seem to answer as one (new servos all ship with the same id).

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace animrt::commission {

struct FoundDevice {
  std::string protocol;  // the robot file's protocol name: dynamixel2, feetech, maestro
  int baud = 0;
  int id = 0;  // bus id (a Maestro: its device number, unknown: 12)
  std::string model;
  std::string firmware;
  std::optional<std::int64_t> position;  // device units (ticks, quarter-us)
  std::optional<double> temperature_c;
  std::optional<double> voltage_v;
  std::optional<bool> torque_on;
  // The device's own limit registers, device units.
  std::optional<std::int64_t> min_limit;
  std::optional<std::int64_t> max_limit;
  std::optional<double> ticks_per_rev;  // of `position`, where it is an angle
  bool multi_turn = false;              // a Dynamixel in extended position mode (4)
  std::string note;                     // what else the user should know (errors, a failed read)
};

struct Collision {
  std::string protocol;
  int baud = 0;
  int id = 0;
  std::string how;  // e.g. "2 answers to one ping", "damaged answers"
};

struct ScanResult {
  std::vector<FoundDevice> devices;
  std::vector<Collision> collisions;
  // Where answers came that are no packet of the protocol asked (a device of
  // another protocol or baud, or noise): "dynamixel2 at 57600: 12 bytes ...".
  std::vector<std::string> garbled;
};

// How long to wait for answers, and which ids to ask where ids are asked one
// by one.
struct ScanLimits {
  std::chrono::microseconds answer_timeout{10'000};
  int first_id = 0;
  int last_id = 252;
  // Progress lines ("dynamixel2 at 57600: ..."); may be empty.
  std::function<void(const std::string&)> progress;
};

}  // namespace animrt::commission
