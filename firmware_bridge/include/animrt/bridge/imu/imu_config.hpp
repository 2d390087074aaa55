#pragma once
// An IMU as the robot file's `imus:` list names it: which part speaks which
// protocol on which port, how it is mounted on the trunk, and how old a
// reading may be before the cycle counts the part as silent.

#include <array>
#include <string>

#include "animrt/core/error.hpp"

namespace animrt {

struct ImuConfig {
  std::string name;
  std::string protocol;  // "bno08x_rvc"
  std::string port;      // serial device; empty with the simulated backend
  int baud = 115200;
  double rate_hz = 100.0;  // the part's report rate
  // Stale after this long without a good frame: the cycle's watch faults
  // the sensor (the figure ramps home), as its watchdog does a silent servo.
  double stale_timeout_s = 0.25;
  // The part's axes in the trunk frame (x forward, y left, z up): yaw, then
  // pitch, then roll, radians.
  std::array<double, 3> mount_ypr_rad{};
  // Simulated part only (`sim:`): without physics the figure is level, or
  // pushed over: from push_at_s on, the trunk rolls (or pitches) at
  // push_rate_rad_s up to push_to_rad.
  struct Push {
    bool on = false;
    bool pitch = false;  // false: roll
    double at_s = 0.0;
    double rate_rad_s = 0.0;
    double to_rad = 0.0;
  } sim_push;
  // Simulated part only: it sends nothing from this time on (s; < 0: never),
  // as a part whose cable came loose.
  double sim_silent_at_s = -1.0;
  // Simulated part on the physics only: how old the torso it reports is
  // (s; at least one loop period, so a lockstep run is deterministic).
  double sim_latency_s = 0.0;  // 0: one report period
  Location where;
};

}  // namespace animrt
