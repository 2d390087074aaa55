#pragma once
// The simulated backend: starts simulated devices for every bus and points
// the bus configs at their endpoints. From there on the runtime drives them
// through exactly the code that drives hardware.

#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure_backend.hpp"
#include "animrt/sim/imu/rvc_sim_imu.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt {

// With `physics` (optional, outlives the devices) the simulated servos take
// their motor state from it (see make_simulated_bus).
// `startup`: factory settings and a state file for the serial servos.
std::vector<std::unique_ptr<SimulatedBus>> start_simulated_devices(
    std::vector<BusConfig>& buses, const Clock& clock, sim::JointPhysics* physics = nullptr,
    const ServoStartup& startup = {});

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

namespace sim {
class MujocoJointPhysics;
}

// The simulated backend a figure is built on (figure.hpp): simulated devices
// for every bus, on the run's clock, optionally driven by physics.
class SimulatedBackend final : public FigureBackend {
 public:
  struct Settings {
    // A MuJoCo model (MJCF) behind the simulated servos: loaded when the
    // devices start, marked at the motion's start and end, and its measures
    // (distance, speed, falls) added to the run's summary.
    std::string physics_model;
    // Or physics of the caller's (outlives the backend), used as it is.
    sim::JointPhysics* physics = nullptr;
  };
  SimulatedBackend();
  explicit SimulatedBackend(Settings settings);
  ~SimulatedBackend() override;

  std::string name() const override { return "sim"; }
  bool keeps_run_clock() const override { return true; }
  // Physics drives dynamixel2 buses only: any other bus is refused.
  void check(const RobotConfig& config, bool lockstep) const override;
  void adjust(RobotConfig& config, bool lockstep) const override;
  std::vector<std::string> start(RobotConfig& config, const Clock& clock) override;
  std::vector<std::string> raise_threads(int priority) override;
  void motion_started(Nanos t0) override;
  void motion_ended() override;
  void report(RunSummary& summary) const override;
  void stop() override;

  // The devices of each bus, in the robot's bus order (after start()).
  std::vector<std::unique_ptr<SimulatedBus>>& devices() { return devices_; }
  // The physics loaded from Settings::physics_model (null without).
  const sim::MujocoJointPhysics* mujoco_physics() const { return own_physics_.get(); }

 private:
  Settings settings_;
  std::unique_ptr<sim::MujocoJointPhysics> own_physics_;  // outlives the devices
  std::vector<std::unique_ptr<SimulatedBus>> devices_;
  std::vector<std::unique_ptr<sim::RvcSimImu>> imus_;
};

}  // namespace animrt
