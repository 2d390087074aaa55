// The runner as a shell: activation is owned whatever ends the run, nothing
// is switched on when setup fails, and on the wall clock a bus that answers
// late never receives a goal that jumps. The buses here are in-process
// devices with ideal motors that log every goal they receive.

#include "animrt/runtime/runner.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "animrt/core/error.hpp"

namespace animrt {
namespace {

struct Goal {
  double t;  // device's wall clock, s
  std::vector<double> positions;
};

// A bus whose devices follow the last goal at once. Can answer late on
// purpose (read sleeps), throw, and report what it received.
class FakeBus : public ActuatorBus {
 public:
  FakeBus(std::string name, std::vector<int> joints, double start = 0.0) {
    config_.name = std::move(name);
    config_.protocol = "fake";
    config_.port = "memory";
    for (std::size_t d = 0; d < joints.size(); ++d) {
      ActuatorBinding a;
      a.joint = "j" + std::to_string(joints[d]);
      a.joint_index = joints[d];
      a.device_id = static_cast<int>(d) + 1;
      config_.actuators.push_back(a);
      DeviceStatus st;
      st.device_id = a.device_id;
      status_.push_back(st);
    }
    positions_.assign(joints.size(), start);
    goals_.reserve(100000);
  }
  const BusConfig& config() const override { return config_; }
  void configure() override { ++configured; }
  void activate() override {
    ++activations;
    if (throw_on_activate) throw DeviceError("bus " + config_.name + ": cannot enable");
    torque_on = true;
  }
  void deactivate() override {
    check_statuses();
    ++deactivations;
    torque_on = false;
  }
  void read(std::span<double> positions) override {
    check_statuses();
    ++reads;
    const int late_ms = late_every > 0 && reads % late_every == 0 ? late_by_ms : 0;
    if (late_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(late_ms));
    if (throw_from > 0 && reads >= throw_from) throw std::runtime_error("adapter unplugged");
    for (std::size_t d = 0; d < positions.size(); ++d) {
      DeviceStatus& st = status_[d];
      if (st.faulted) continue;
      ++st.transactions;
      if (d == 0 && silent_from > 0 && reads >= silent_from) {
        ++st.timeouts;
        st.health = DeviceHealth::timeout;
        continue;
      }
      positions[d] = positions_[d];
      st.health = DeviceHealth::ok;
    }
    mine_.assign(status_.begin(), status_.end());
  }
  void write(std::span<const double> positions) override {
    check_statuses();
    positions_.assign(positions.begin(), positions.end());
    if (goals_.size() < goals_.capacity()) {
      goals_.push_back(Goal{to_seconds(wall_.now()), positions_});
    }
  }
  void mark_faulted(std::size_t device) override {
    check_statuses();
    ActuatorBus::mark_faulted(device);
    mine_.assign(status_.begin(), status_.end());
  }
  std::span<DeviceStatus> devices() override { return status_; }

  // Counts statuses that changed since this bus last wrote them: someone
  // else wrote them.
  void check_statuses() {
    if (mine_.size() != status_.size()) mine_.assign(status_.begin(), status_.end());
    for (std::size_t d = 0; d < status_.size(); ++d) {
      const DeviceStatus& a = status_[d];
      const DeviceStatus& b = mine_[d];
      if (a.health != b.health || a.faulted != b.faulted || a.transactions != b.transactions ||
          a.timeouts != b.timeouts || a.protocol_errors != b.protocol_errors) {
        ++foreign_writes;
      }
    }
    mine_.assign(status_.begin(), status_.end());
  }

  const std::vector<Goal>& goals() const { return goals_; }

  int configured = 0, activations = 0, deactivations = 0;
  bool torque_on = false;
  bool throw_on_activate = false;
  int late_every = 0;  // every n-th read is late
  int late_by_ms = 0;
  int throw_from = 0;   // from the n-th read on, read() throws
  int silent_from = 0;  // from the n-th read on, device 0 does not answer
  std::atomic<int> foreign_writes{0};

 private:
  BusConfig config_;
  std::vector<DeviceStatus> status_;
  std::vector<double> positions_;
  std::vector<Goal> goals_;
  std::vector<DeviceStatus> mine_;  // the statuses as this bus last left them
  int reads = 0;
  MonotonicClock wall_;
};

class SineSource : public MotionSource {
 public:
  explicit SineSource(std::size_t n, double amplitude = 1.0, double rate = 2.0)
      : amplitude_(amplitude), rate_(rate) {
    for (std::size_t j = 0; j < n; ++j) driven_.push_back(static_cast<int>(j));
  }
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override {
    for (std::size_t j = 0; j < targets.size(); ++j) targets[j] = amplitude_ * std::sin(rate_ * t);
  }

 private:
  double amplitude_, rate_;
  std::vector<int> driven_;
};

RobotConfig two_bus_config(double velocity = 2.0) {
  RobotConfig c;
  c.file = "test.yaml";
  c.name = "test";
  c.rate_hz = 200.0;
  c.safety.start_ramp_s = 0.2;
  c.safety.stop_ramp_s = 0.2;
  c.motion.type = "gait";
  c.motion.file = "test_gait.yaml";
  for (int j = 0; j < 4; ++j) {
    JointSpec s;
    s.name = "j" + std::to_string(j);
    s.limits = JointLimits{-1.5, 1.5, velocity, 40.0};
    c.joints.push_back(s);
  }
  return c;
}

struct Rig {
  explicit Rig(RobotConfig config = two_bus_config(), double start = 0.0) {
    auto a = std::make_unique<FakeBus>("a", std::vector<int>{0, 1}, start);
    auto b = std::make_unique<FakeBus>("b", std::vector<int>{2, 3}, start);
    bus_a = a.get();
    bus_b = b.get();
    std::vector<std::unique_ptr<ActuatorBus>> buses;
    buses.push_back(std::move(a));
    buses.push_back(std::move(b));
    runner = std::make_unique<Runner>(config, std::move(buses),
                                      std::make_unique<SineSource>(config.joints.size()));
  }
  FakeBus* bus_a;
  FakeBus* bus_b;
  std::unique_ptr<Runner> runner;
  ManualClock clock;
};

RunOptions lockstep(Rig& rig, double duration) {
  RunOptions o;
  o.duration_s = duration;
  o.lockstep_clock = &rig.clock;
  return o;
}

TEST(Runner, AnExceptionInTheLoopStillSwitchesEveryBusOff) {
  Rig rig;
  RunOptions o = lockstep(rig, 1.0);
  o.on_motion_start = [](Nanos) { throw std::runtime_error("sound card gone"); };
  EXPECT_THROW(rig.runner->run(o), std::runtime_error);
  EXPECT_EQ(rig.bus_a->activations, 1);
  EXPECT_FALSE(rig.bus_a->torque_on);
  EXPECT_FALSE(rig.bus_b->torque_on);
  EXPECT_EQ(rig.bus_b->deactivations, 1);
}

TEST(Runner, TheHeartbeatCountsEveryCycleAndEndsWithTheRun) {
  Rig rig;
  RunHeartbeat heartbeat;
  RunOptions o = lockstep(rig, 0.5);
  o.heartbeat = &heartbeat;
  const RunSummary summary = rig.runner->run(o);
  EXPECT_GT(summary.cycles, 0u);
  EXPECT_EQ(heartbeat.cycles(), summary.cycles);
  EXPECT_TRUE(heartbeat.moved());
  EXPECT_EQ(heartbeat.stage(), RunHeartbeat::Stage::ended);
}

TEST(Runner, ABusThatFailsToActivateIsSwitchedOffWithTheOnesBeforeIt) {
  Rig rig;
  rig.bus_b->throw_on_activate = true;
  EXPECT_THROW(rig.runner->run(lockstep(rig, 1.0)), DeviceError);
  EXPECT_EQ(rig.bus_a->deactivations, 1);
  EXPECT_EQ(rig.bus_b->deactivations, 1);  // it may have enabled some devices
  EXPECT_FALSE(rig.bus_a->torque_on);
  EXPECT_TRUE(rig.bus_a->goals().empty());
}

TEST(Runner, AnUnwritableTelemetryFileStopsTheRunBeforeAnythingIsSwitchedOn) {
  Rig rig;
  RunOptions o = lockstep(rig, 1.0);
  o.telemetry_path = "/nonexistent-folder/telemetry.csv";
  EXPECT_THROW(rig.runner->run(o), std::runtime_error);
  EXPECT_EQ(rig.bus_a->activations, 0);
  EXPECT_EQ(rig.bus_b->activations, 0);
}

TEST(Runner, AStartRampLongerThanItsLimitIsRefusedBeforeTorqueGoesOn) {
  RobotConfig config = two_bus_config(0.01);  // rad/s: 1.2 rad takes minutes
  config.safety.start_ramp_max_s = 20.0;
  Rig rig(config, 1.2);
  try {
    rig.runner->run(lockstep(rig, 1.0));
    FAIL() << "expected a DeviceError";
  } catch (const DeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("start ramp: joint j0 is measured at 68.8 deg and the motion starts at "
                        "0.0 deg"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("safety.start_ramp_max_s (20 s)"), std::string::npos) << what;
  }
  EXPECT_EQ(rig.bus_a->activations, 0);
}

TEST(Runner, AStopRequestedDuringBringUpSwitchesNothingOn) {
  Rig rig;
  RunControls controls;
  controls.stop = true;
  RunOptions o = lockstep(rig, 1.0);
  o.controls = &controls;
  const RunSummary s = rig.runner->run(o);
  EXPECT_EQ(s.end_reason, EndReason::signal);
  EXPECT_EQ(s.exit_code(), 0);
  EXPECT_EQ(rig.bus_a->configured, 1);
  EXPECT_EQ(rig.bus_a->activations, 0);
  EXPECT_EQ(rig.bus_b->activations, 0);
  EXPECT_TRUE(rig.bus_a->goals().empty());
}

TEST(Runner, ASecondStopRequestCutsTorqueWithExitCodeFive) {
  Rig rig;
  RunControls controls;
  RunOptions o = lockstep(rig, 0.0);
  o.controls = &controls;
  o.on_motion_start = [&](Nanos) { controls.stop = true; };
  o.on_motion_end = [&] { controls.abort = true; };
  const RunSummary s = rig.runner->run(o);
  EXPECT_EQ(s.end_reason, EndReason::signal);
  EXPECT_EQ(s.exit_code(), 5);
  EXPECT_NE(s.torque_cut.find("second stop request"), std::string::npos) << s.torque_cut;
  EXPECT_NE(format_summary(s).find("TORQUE CUT second stop request"), std::string::npos);
  EXPECT_FALSE(rig.bus_a->torque_on);
}

// Wall clock: bus b answers 12 ms late on every fourth read (the period is
// 5 ms, the read budget 3 ms after the deadline), so it misses cycles. On
// the device side no goal may be further from the one before than the
// velocity limit allows over the time between them.
TEST(Runner, OnTheWallClockALateBusNeverReceivesAJump) {
  Rig rig(two_bus_config(2.0));
  rig.bus_b->late_every = 4;
  rig.bus_b->late_by_ms = 12;
  RunOptions o;
  o.duration_s = 1.5;
  o.request_realtime = false;
  const RunSummary s = rig.runner->run(o);
  EXPECT_EQ(s.exit_code(), 0) << format_summary(s);
  ASSERT_EQ(s.buses.size(), 2u);
  EXPECT_GT(s.buses[1].late_cycles, 20u) << format_summary(s);
  const auto& goals = rig.bus_b->goals();
  ASSERT_GT(goals.size(), 50u);
  // Between two goals the device received lies at most one filter step
  // (2 rad/s * 5 ms), however many cycles the bus missed in between: its
  // joints held while it was late. (Wall-clock gaps between writes depend on
  // the machine's load, so the bound is per write, not per second.)
  for (std::size_t k = 1; k < goals.size(); ++k) {
    for (std::size_t d = 0; d < 2; ++d) {
      EXPECT_LE(std::abs(goals[k].positions[d] - goals[k - 1].positions[d]), 2.0 * 0.005 + 1e-9)
          << "goal " << k << " device " << d;
    }
  }
}

// A bus's statuses have one writer, the bus. What the runner knows beyond
// them (a bus whose read throws, its watchdog's faults) still reaches the
// summary and the watchdog, and a faulted device is asked no more.
TEST(Runner, ABusAloneWritesItsStatusesAndTheSummaryCombinesWhatTheLoopKnows) {
  Rig rig;
  rig.bus_a->silent_from = 40;  // j0 stops answering after 0.2 s
  rig.bus_b->throw_from = 40;   // bus b's reads throw from then on
  const RunSummary s = rig.runner->run(lockstep(rig, 3.0));
  rig.bus_a->check_statuses();
  rig.bus_b->check_statuses();
  EXPECT_EQ(rig.bus_a->foreign_writes.load(), 0);
  EXPECT_EQ(rig.bus_b->foreign_writes.load(), 0);
  // The faults reached the buses, which skip those devices now.
  EXPECT_TRUE(rig.bus_a->devices()[0].faulted);
  EXPECT_FALSE(rig.bus_a->devices()[1].faulted);
  EXPECT_TRUE(rig.bus_b->devices()[0].faulted);
  EXPECT_TRUE(rig.bus_b->devices()[1].faulted);
  EXPECT_EQ(s.end_reason, EndReason::fault) << format_summary(s);
  EXPECT_EQ(s.faults.size(), 3u) << format_summary(s);
  ASSERT_EQ(s.devices.size(), 4u);
  // j0: its own bus counted its timeouts; j1 answered throughout.
  EXPECT_TRUE(s.devices[0].status.faulted);
  EXPECT_EQ(s.devices[0].status.health, DeviceHealth::timeout);
  EXPECT_GT(s.devices[0].status.timeouts, 0u);
  EXPECT_FALSE(s.devices[1].status.faulted);
  EXPECT_EQ(s.devices[1].status.health, DeviceHealth::ok);
  // j2, j3: bus b never counted a timeout (it threw); the loop did.
  for (std::size_t d = 2; d < 4; ++d) {
    EXPECT_TRUE(s.devices[d].status.faulted) << d;
    EXPECT_EQ(s.devices[d].status.health, DeviceHealth::timeout) << d;
    EXPECT_GT(s.devices[d].status.timeouts, 0u) << d;
    EXPECT_EQ(rig.bus_b->devices()[d - 2].timeouts, 0u) << d;
  }
  EXPECT_NE(format_summary(s).find("j2             FAULTED"), std::string::npos)
      << format_summary(s);
}

// A record that could not be written is exit 6 and its own summary line;
// what happened to the figure (a fault, a torque cut) comes first.
// Records the clock the run hands over and what it read on it.
class ClockedSource final : public SineSource {
 public:
  explicit ClockedSource(std::size_t n) : SineSource(n) {}
  void start(const MotionClock& clock) override {
    ++starts;
    given = clock;
  }
  void stop() override { ++stops; }
  void sample(double t, std::span<double> targets) const override {
    if (starts > 0 && stops == 0 && first_t < 0 && t > 0) {
      first_t = t;
      clock_then = given.clock->now();
    }
    SineSource::sample(t, targets);
  }
  int starts = 0, stops = 0;
  MotionClock given;
  mutable double first_t = -1.0;
  mutable Nanos clock_then = -1;
};

TEST(Runner, TheMotionReadsTheRunsClockFromItsStartAndLetsGoOfItOnEveryWayOut) {
  for (const bool throws : {false, true}) {
    auto source = std::make_unique<ClockedSource>(4);
    ClockedSource* clocked = source.get();
    std::vector<std::unique_ptr<ActuatorBus>> buses;
    buses.push_back(std::make_unique<FakeBus>("a", std::vector<int>{0, 1, 2, 3}));
    RobotConfig config = two_bus_config();
    Runner runner(config, std::move(buses), std::move(source));
    ManualClock clock(5'000'000'000);
    RunOptions o;
    o.duration_s = 0.5;
    o.lockstep_clock = &clock;
    Nanos t0 = -1;
    o.on_motion_start = [&](Nanos t) {
      t0 = t;
      if (throws) throw std::runtime_error("sound card gone");
    };
    if (throws) {
      EXPECT_THROW(runner.run(o), std::runtime_error);
    } else {
      runner.run(o);
    }
    EXPECT_EQ(clocked->starts, 1) << throws;
    EXPECT_EQ(clocked->given.clock, &clock);
    EXPECT_TRUE(clocked->given.lockstep);
    EXPECT_EQ(clocked->given.start, t0);  // the motion's t = 0 on the run's clock
    EXPECT_GT(t0, Nanos{5'000'000'000});  // after the start ramp
    EXPECT_EQ(clocked->stops, 1) << throws;
    if (!throws) {
      // The clock read in a sample is the motion's start plus the sample's t.
      ASSERT_GT(clocked->first_t, 0.0);
      EXPECT_EQ(clocked->clock_then, t0 + from_seconds(clocked->first_t));
    }
  }
}

TEST(RunSummary, ALostRecordIsExitSixUnlessTheFigureFaredWorse) {
  RunSummary s;
  s.telemetry_file = "/dev/full";
  s.telemetry_records = 0;
  s.telemetry_lost = 42;
  s.telemetry_error = "No space left on device";
  EXPECT_EQ(s.exit_code(), 6);
  EXPECT_NE(format_summary(s).find("RECORD LOST telemetry: 42 of 42 records could not be written "
                                   "to /dev/full: No space left on device"),
            std::string::npos)
      << format_summary(s);
  s.torque_cut = "second stop request";
  EXPECT_EQ(s.exit_code(), 5);
  s.end_reason = EndReason::fault;
  EXPECT_EQ(s.exit_code(), 4);
}

}  // namespace
}  // namespace animrt
