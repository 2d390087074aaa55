#pragma once
// A robot file run against its simulated devices, the setup the integration
// tests share: the robot loaded and built into a figure (figure.hpp) on the
// simulated backend, on a lockstep or the wall clock. Each bus is wrapped in a
// WatchedBus, which forwards every call to the real bus and lets a test act
// on the calling thread before a read or write (make the bus late, inject a
// fault at a given cycle) and open an allocation window at the first cycle.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "animrt/sim/simulated_bus.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace sim {
class JointPhysics;
}

namespace test {

// Calls on_sample(t) on the loop thread before each sample of the inner source.
class ProbeSource final : public MotionSource {
 public:
  explicit ProbeSource(std::unique_ptr<MotionSource> inner) : inner_(std::move(inner)) {}
  std::span<const int> driven_joints() const override { return inner_->driven_joints(); }
  void sample(double t, std::span<double> targets) const override {
    if (on_sample) on_sample(t);
    inner_->sample(t, targets);
  }
  void steer(const MotionCommand& command) override { inner_->steer(command); }
  void sense(const Sensors& sensors) override { inner_->sense(sensors); }
  double wind_down(double t, double granted_s) override { return inner_->wind_down(t, granted_s); }
  void control(const ShowCommand& command, double t) override { inner_->control(command, t); }
  ShowPosition show_position(double t) const override { return inner_->show_position(t); }
  void start(const MotionClock& clock) override { inner_->start(clock); }
  void stop() override { inner_->stop(); }
  std::function<void(double)> on_sample;

 private:
  std::unique_ptr<MotionSource> inner_;
};

enum class BusCall { configure, activate, read, write, deactivate };

// The real bus behind a hook, called on the calling thread before each call
// is forwarded (bus index, call, how many calls of that kind came before).
class WatchedBus final : public ActuatorBus {
 public:
  using Hook = std::function<void(std::size_t bus, BusCall call, std::uint64_t index)>;
  WatchedBus(std::unique_ptr<ActuatorBus> inner, std::size_t index, const Hook& hook)
      : inner_(std::move(inner)), index_(index), hook_(hook) {}

  const BusConfig& config() const override { return inner_->config(); }
  void configure() override {
    notify(BusCall::configure);
    inner_->configure();
  }
  void activate() override {
    notify(BusCall::activate);
    inner_->activate();
  }
  void arm_device_guard() override { inner_->arm_device_guard(); }
  void deactivate() override {
    notify(BusCall::deactivate);
    inner_->deactivate();
  }
  void read(std::span<double> positions) override {
    notify(BusCall::read);
    inner_->read(positions);
  }
  void write(std::span<const double> positions) override {
    notify(BusCall::write);
    inner_->write(positions);
  }
  std::span<DeviceStatus> devices() override { return inner_->devices(); }
  void mark_faulted(std::size_t device) override { inner_->mark_faulted(device); }
  void switch_off(std::size_t device) override { inner_->switch_off(device); }
  bool reads_health() const override { return inner_->reads_health(); }

  ActuatorBus& inner() { return *inner_; }
  std::uint64_t calls(BusCall call) const { return calls_[static_cast<int>(call)].load(); }

 private:
  void notify(BusCall call) {
    const std::uint64_t n = calls_[static_cast<int>(call)].fetch_add(1);
    if (hook_) hook_(index_, call, n);
  }
  std::unique_ptr<ActuatorBus> inner_;
  std::size_t index_;
  const Hook& hook_;
  std::atomic<std::uint64_t> calls_[5]{};
};

struct RigSettings {
  bool lockstep = true;
  // Every bus's answer timeout is raised to at least this, and in lockstep
  // to at least kLockstepMinTimeoutS: a loaded CI machine must not cause
  // timeouts.
  double min_bus_timeout_s = 0.05;
  bool wire_time = false;                         // emulate Dynamixel wire time
  std::function<void(RobotConfig&)> edit;         // before the devices start
  sim::JointPhysics* physics = nullptr;           // dynamixel2 buses only
  std::function<void(LoadedRobot&)> edit_motion;  // e.g. replace the motion source
};

class SimRig {
 public:
  explicit SimRig(const std::string& robot_file, const RigSettings& settings = {});
  ~SimRig();
  SimRig(const SimRig&) = delete;
  SimRig& operator=(const SimRig&) = delete;

  const RobotConfig& config() const { return robot.config; }
  const Clock& clock() const;
  SimulatedBus& sim(const std::string& bus_name);
  // The real bus (behind its WatchedBus) and the wrapper.
  ActuatorBus& bus(std::size_t index) { return watched_[index]->inner(); }
  WatchedBus& watched(std::size_t index) { return *watched_[index]; }
  const Runner& runner() const { return figure_->runner(); }
  Figure& figure() { return *figure_; }

  // Options for a run of `duration` s (0: until a stop request), with
  // telemetry to `telemetry` if not empty.
  RunOptions options(double duration, const std::string& telemetry = "");
  RunSummary run(double duration, const std::string& telemetry = "");
  RunSummary run(const RunOptions& options);
  // A run under `watch`: its window opens at the first read after every bus
  // is active (the first cycle) and closes at the first deactivate (after
  // the last cycle); the phases follow on_motion_start / on_motion_end.
  RunSummary run_watching(RunAllocationWatch& watch, const RunOptions& options);
  // Cycles (reads of bus 0) seen in each phase of the last watched run.
  std::uint64_t cycles_in(RunPhase phase) const {
    return phase_cycles_[static_cast<int>(phase)].load();
  }

  LoadedRobot robot;  // the config points at the simulated devices

 private:
  SimulatedBackend backend_;

 public:
  std::vector<std::unique_ptr<SimulatedBus>>& sims;  // the backend's, per bus
  ProbeSource* probe = nullptr;
  // Called before every forwarded bus call (see WatchedBus); set before run().
  WatchedBus::Hook on_bus_call;

 private:
  void bus_call(std::size_t bus, BusCall call, std::uint64_t index);

  std::vector<WatchedBus*> watched_;
  WatchedBus::Hook hook_;
  std::unique_ptr<Figure> figure_;
  RunAllocationWatch* watch_ = nullptr;
  std::atomic<int> active_buses_{0};
  std::atomic<int> phase_{0};
  std::atomic<bool> in_window_{false};
  std::atomic<std::uint64_t> phase_cycles_[3]{};
};

// What a lockstep run compared bit for bit with another must not have had: a
// fault, a bus cycle without a fresh read (late), or a device's timeout,
// CRC, protocol or hardware error or exception. One line per problem; empty
// when the run was clean.
std::string lockstep_problems(const RunSummary& s);

// The first line at which two text files differ, both lines quoted; empty
// when they are the same (and both could be opened).
std::string first_difference(const std::string& file_a, const std::string& file_b);

}  // namespace test
}  // namespace animrt
