#pragma once
// The simulated backend: starts simulated devices for every bus and points
// the bus configs at their endpoints. From there on the runtime drives them
// through exactly the code that drives hardware.

#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt {

// With `physics` (optional, outlives the devices) the simulated servos take
// their motor state from it (see make_simulated_bus).
std::vector<std::unique_ptr<SimulatedBus>> start_simulated_devices(
    std::vector<BusConfig>& buses, const Clock& clock, sim::JointPhysics* physics = nullptr);

// Puts every simulated bus's thread at SCHED_FIFO `priority` (a real-time
// run gives them the one just below its bus I/O threads: a busy host must
// not make a simulated servo miss its watchdog). One line per bus that could
// not have it, saying why.
std::vector<std::string> raise_simulated_devices(
    const std::vector<std::unique_ptr<SimulatedBus>>& simulated, int priority);

// Simulated devices answer in no simulated time, so in a lockstep run a bus
// timeout measures only how busy the host is: every bus's timeout is raised
// to at least kLockstepMinTimeoutS, so that a loaded machine does not make
// a device look silent (and two lockstep runs differ).
inline constexpr double kLockstepMinTimeoutS = 0.25;
void widen_timeouts_for_lockstep(std::vector<BusConfig>& buses);

}  // namespace animrt
