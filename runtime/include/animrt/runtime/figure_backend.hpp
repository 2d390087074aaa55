#pragma once
// What stands behind a figure's buses: the hardware the bus configs name, or
// simulated devices started for them. The runtime does not know which: a
// backend is built outside the runtime library (the simulated one in sim)
// and handed to the figure builder (figure.hpp). Header only, so a backend
// can implement it without linking the runtime.

#include <memory>
#include <string>
#include <vector>

#include "animrt/core/clock.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/runtime/run_summary.hpp"

namespace animrt {

class FigureBackend {
 public:
  virtual ~FigureBackend() = default;
  // "hardware" or "sim": the run's report names it.
  virtual std::string name() const = 0;
  // Whether the devices keep the run's clock, so that a lockstep run (a
  // simulated clock) can drive them. Hardware keeps the wall's.
  virtual bool keeps_run_clock() const = 0;
  // Refuses, before anything starts, a robot this backend cannot stand
  // behind (throws InputError naming the robot file's key).
  virtual void check(const RobotConfig& config, bool lockstep) const {
    (void)config;
    (void)lockstep;
  }
  // Adjusts the bus configs to the backend before anything starts (a
  // simulated device answers in no simulated time: lockstep timeouts widen,
  // and the wire is not emulated).
  virtual void adjust(RobotConfig& config, bool lockstep) const {
    (void)config;
    (void)lockstep;
  }
  // Starts what stands behind the buses on `clock` and points the bus
  // configs at it. Returns lines for the log.
  virtual std::vector<std::string> start(RobotConfig& config, const Clock& clock) {
    (void)config;
    (void)clock;
    return {};
  }
  // RunOptions::raise_device_threads: the backend's own threads.
  virtual std::vector<std::string> raise_threads(int priority) {
    (void)priority;
    return {};
  }
  // Called from inside the cycle when the motion starts and ends (same
  // rules as RunOptions::on_motion_start).
  virtual void motion_started(Nanos t0) { (void)t0; }
  virtual void motion_ended() {}
  // What the backend measured, added to the run's summary.
  virtual void report(RunSummary& summary) const { (void)summary; }
  // Stops what start() started; the buses have closed.
  virtual void stop() {}
};

// The real devices, at the ports the bus configs name.
class HardwareBackend final : public FigureBackend {
 public:
  std::string name() const override { return "hardware"; }
  bool keeps_run_clock() const override { return false; }
  // A real IMU needs its port (a simulated one is given a pty).
  void check(const RobotConfig& config, bool lockstep) const override {
    (void)lockstep;
    for (std::size_t i = 0; i < config.imus.size(); ++i) {
      if (config.imus[i].port.empty()) {
        throw InputError(config.imus[i].where, "imus[" + std::to_string(i) + "].port",
                         "expected the serial port of IMU " + config.imus[i].name +
                             " (needed on hardware), found none");
      }
    }
  }
};

}  // namespace animrt
