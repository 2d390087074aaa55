#pragma once
// The control interface of `animrt sim`: what a person does to simulated
// serial servos on the bench, from another process. A Unix stream socket,
// one command per line, one reply line each ("ok ..." or "error: <why>"):
//
//   hand BUS ID TICKS   turn the shaft of servo ID to raw position TICKS
//                       (refused with "error: torque is on" while it is)
//   hand-path BUS ID READS TICKS...
//                       a test aid: the hand turns it to each TICKS in turn,
//                       one step after every READS reads of its position
//                       (SimulatedBus::hand_path)
//   get BUS ID          "ok ticks=<present> torque=<0|1> id=<ID register> baud=<baud>"
//   plug BUS INDEX      connect the INDEX-th device of the bus (0-based, the
//   unplug BUS INDEX    robot file's order) / disconnect it
//
// BUS is the bus's name in the robot file, ID the id the robot file gives
// the servo (whatever its ID register says now). docs/cli.md documents it.

#include <array>
#include <atomic>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "animrt/sim/simulated_bus.hpp"

namespace animrt::sim {

// A bus by its robot-file name.
using NamedBuses = std::vector<std::pair<std::string, SimulatedBus*>>;

// One command line (without its newline) -> its reply line (without one).
std::string control_command(const NamedBuses& buses, std::string_view line);

class ControlSocket {
 public:
  // Listens at `path` (a stale socket there is replaced); throws DeviceError
  // if it cannot. The buses outlive the socket.
  ControlSocket(std::string path, NamedBuses buses);
  // Stops serving and removes the socket file.
  ~ControlSocket();
  ControlSocket(const ControlSocket&) = delete;
  ControlSocket& operator=(const ControlSocket&) = delete;

  const std::string& path() const { return path_; }

 private:
  void serve();

  std::string path_;
  NamedBuses buses_;
  int listen_fd_ = -1;
  std::array<int, 2> wake_{-1, -1};
  std::thread thread_;
};

}  // namespace animrt::sim
