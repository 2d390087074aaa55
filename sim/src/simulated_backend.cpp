#include "animrt/sim/simulated_backend.hpp"

#include <algorithm>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/mujoco/mujoco_physics.hpp"

namespace animrt {

std::vector<std::unique_ptr<SimulatedBus>> start_simulated_devices(std::vector<BusConfig>& buses,
                                                                   const Clock& clock,
                                                                   sim::JointPhysics* physics,
                                                                   const ServoStartup& startup) {
  std::vector<std::unique_ptr<SimulatedBus>> simulated;
  for (auto& bus : buses) {
    auto sim = make_simulated_bus(bus, clock, physics, startup);
    sim->start();
    bus.port = sim->endpoint();
    bus.lockstep_line = sim->lockstep_line();
    simulated.push_back(std::move(sim));
  }
  return simulated;
}

std::vector<std::string> raise_simulated_devices(
    const std::vector<std::unique_ptr<SimulatedBus>>& simulated, int priority) {
  std::vector<std::string> notes;
  for (const auto& bus : simulated) {
    if (std::string why = bus->raise_priority(priority); !why.empty()) {
      notes.push_back(bus->describe() + ": " + why + ", normal thread");
    }
  }
  return notes;
}

void widen_timeouts_for_lockstep(std::vector<BusConfig>& buses) {
  for (BusConfig& bus : buses) bus.timeout_s = std::max(bus.timeout_s, kLockstepMinTimeoutS);
}

SimulatedBackend::SimulatedBackend() = default;
SimulatedBackend::SimulatedBackend(Settings settings) : settings_(std::move(settings)) {}
SimulatedBackend::~SimulatedBackend() { stop(); }

void SimulatedBackend::check(const RobotConfig& config, bool lockstep) const {
  (void)lockstep;
  if (settings_.physics_model.empty() && settings_.physics == nullptr) return;
  for (const BusConfig& bus : config.buses) {
    if (bus.protocol != "dynamixel2") {
      throw InputError(
          bus.where, "protocol",
          "physics drives only dynamixel2 buses; bus '" + bus.name + "' is " + bus.protocol);
    }
  }
}

void SimulatedBackend::adjust(RobotConfig& config, bool lockstep) const {
  if (!lockstep) return;
  widen_timeouts_for_lockstep(config.buses);
  // Nor does the wire take simulated time: its emulation (real time, for
  // real-time runs) would only make a lockstep run slower, never different.
  for (BusConfig& bus : config.buses) bus.sim.wire_time = false;
}

std::vector<std::string> SimulatedBackend::start(RobotConfig& config, const Clock& clock) {
  std::vector<std::string> lines;
  sim::JointPhysics* physics = settings_.physics;
  if (!settings_.physics_model.empty()) {
    own_physics_ = std::make_unique<sim::MujocoJointPhysics>(settings_.physics_model, config.joints,
                                                             config.file, clock.now());
    physics = own_physics_.get();
    lines.push_back("physics: " + settings_.physics_model + " drives the simulated servos");
    // A gait's feet are counted as the gait fitness counts them, so the
    // run's stride and duty compare with gait measure's.
    if (config.motion.type == "gait") {
      own_physics_->measure_feet(load_gait_file(config.motion.file).stride_frequency());
    }
  }
  devices_ = start_simulated_devices(config.buses, clock, physics);
  for (const auto& device : devices_) lines.push_back("simulated devices: " + device->describe());
  // Each IMU a simulated part on a pty: on the physics' torso, or without
  // physics level or pushed over as the robot file's `sim:` says.
  for (ImuConfig& imu : config.imus) {
    sim::TrunkProvider trunk = sim::scripted_trunk(imu.sim_push);
    std::string source = imu.sim_push.on ? "pushed over by the robot file's script" : "level";
    if (own_physics_) {
      // A frame reports the torso one report period before it is sent, or as
      // long before as `latency_ms` says (at least a loop period): the
      // physics has got there by then, so a lockstep run reads the same
      // frames whichever thread runs first.
      own_physics_->keep_torso_history();
      const double age = imu.sim_latency_s > 0.0 ? imu.sim_latency_s : 1.0 / imu.rate_hz;
      trunk = [physics = own_physics_.get(), age](double t) {
        const sim::TorsoMotion torso = physics->torso_motion_at(t - age);
        return sim::TrunkState{torso.quat, torso.accel_m_s2};
      };
      source = "on the physics' torso";
    }
    imus_.push_back(std::make_unique<sim::RvcSimImu>(imu, clock, clock.now(), std::move(trunk)));
    imu.port = imus_.back()->port();
    lines.push_back("simulated IMU " + imu.name + " (" + imu.protocol + ") on " + imu.port + ", " +
                    source);
  }
  return lines;
}

std::vector<std::string> SimulatedBackend::raise_threads(int priority) {
  return raise_simulated_devices(devices_, priority);
}

void SimulatedBackend::motion_started(Nanos t0) {
  (void)t0;
  if (own_physics_) own_physics_->mark_motion_start();
}

void SimulatedBackend::motion_ended() {
  if (own_physics_) own_physics_->mark_motion_end();
}

void SimulatedBackend::report(RunSummary& summary) const {
  if (!own_physics_) return;
  const sim::PhysicsMeasures m = own_physics_->measures();
  PhysicsReport report;
  report.model = m.model_file;
  report.timestep_s = m.timestep_s;
  report.simulated_s = m.simulated_s;
  report.forward_m = m.forward_m;
  report.sideways_m = m.sideways_m;
  report.motion_s = m.motion_s;
  report.motion_forward_m = m.motion_forward_m;
  report.average_speed_m_s = m.motion_s > 0 ? m.motion_forward_m / m.motion_s : 0.0;
  report.falls = m.falls;
  report.first_fall_s = m.first_fall_s;
  report.lockstep_waits_timed_out = m.lockstep_waits_timed_out;
  report.stride_length_m = m.stride_length_m;
  report.duty_factor = m.duty_factor;
  summary.physics = report;
}

void SimulatedBackend::stop() {
  imus_.clear();
  devices_.clear();
}

}  // namespace animrt
