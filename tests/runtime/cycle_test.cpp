// The cycle as a plain function: every edge of the safety path, without
// threads, clocks or devices. The "devices" here are the test's own vectors:
// each follows the goal it was last written, unless a test says otherwise.

#include "animrt/runtime/cycle.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>

#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

constexpr double kRate = 100.0;

class LambdaSource : public MotionSource {
 public:
  explicit LambdaSource(std::size_t joints) {
    for (std::size_t j = 0; j < joints; ++j) driven_.push_back(static_cast<int>(j));
  }
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override {
    for (std::size_t j = 0; j < targets.size(); ++j) targets[j] = fn(j, t);
  }
  void steer(const MotionCommand& command) override { steered = command; }
  double wind_down(double t, double granted_s) override {
    wound_at.push_back(t);
    granted.push_back(granted_s);
    return wind;
  }

  std::function<double(std::size_t, double)> fn = [](std::size_t, double) { return 0.0; };
  MotionCommand steered{-1.0, -1.0};
  double wind = 0.0;             // what wind_down() asks for (s)
  std::vector<double> wound_at;  // motion times wind_down() was called at
  std::vector<double> granted;   // the time each call granted

 private:
  std::vector<int> driven_;
};

// Two buses of two joints each: bus 0 drives joints 0 and 1, bus 1 drives 2 and 3.
RobotModel two_bus_model() {
  RobotModel m;
  m.name = "test";
  m.rate_hz = kRate;
  m.period = from_seconds(1.0 / kRate);
  m.dt = 1.0 / kRate;
  m.safety.start_ramp_s = 0.5;
  m.safety.stop_ramp_s = 0.5;
  m.motion = "gait test.yaml";
  for (int j = 0; j < 4; ++j) {
    m.joint_names.push_back("j" + std::to_string(j));
    m.limits.push_back(JointLimits{-1.5, 1.5, 2.0, 20.0});
    m.home.push_back(0.0);
    m.prismatic.push_back(0);
    m.following_error.push_back(m.safety.following_error_rad);
    m.slots.push_back(JointSlot{static_cast<std::size_t>(j / 2), static_cast<std::size_t>(j % 2)});
  }
  m.buses.push_back(BusModel{"a", {0, 1}, {1, 2}});
  m.buses.push_back(BusModel{"b", {2, 3}, {3, 4}});
  return m;
}

// Runs cycles of a model against ideal devices (measured = last goal written).
struct Bench {
  explicit Bench(RobotModel m) : model(std::move(m)), motion(model.joint_count()), state(model) {
    for (const BusModel& bus : model.buses) {
      positions.emplace_back(bus.joint.size(), 0.0);
      health.emplace_back(bus.joint.size(), DeviceHealth::ok);
    }
    io.resize(model.buses.size());
    fresh.assign(model.buses.size(), 1);
  }
  void begin() {
    std::vector<double> measured(model.joint_count(), 0.0);
    std::vector<double> first(model.home);
    source().sample(0.0, first);
    state.begin(model, measured, first);
  }
  const CycleOutputs& cycle() {
    for (std::size_t b = 0; b < io.size(); ++b) {
      io[b] = BusIo{fresh[b] != 0, positions[b], health[b]};
    }
    in.t = static_cast<double>(count) / kRate;
    in.buses = io;
    const CycleOutputs& out = step(model, source(), state, in);
    for (std::size_t b = 0; b < io.size(); ++b) {
      if (!out.write[b]) continue;
      if (follow) positions[b] = out.bus_commands[b];
      written[b].push_back(out.bus_commands[b]);
    }
    for (const CycleEvent& e : out.events) events.push_back(e);
    ++count;
    return out;
  }
  // Runs until the phase is reached (or `limit` cycles).
  void run_until(Phase phase, int limit = 10000) {
    for (int i = 0; i < limit && state.phase() != phase && !state.done(); ++i) cycle();
  }
  bool has(EventKind kind) const {
    for (const auto& e : events)
      if (e.kind == kind) return true;
    return false;
  }
  const CycleEvent* first(EventKind kind) const {
    for (const auto& e : events)
      if (e.kind == kind) return &e;
    return nullptr;
  }

  MotionSource& source() { return show ? *show : static_cast<MotionSource&>(motion); }

  RobotModel model;
  LambdaSource motion;
  std::unique_ptr<MotionSource> show;  // when set, the motion instead of `motion`
  CycleState state;
  std::vector<std::vector<double>> positions;
  std::vector<std::vector<DeviceHealth>> health;
  std::vector<BusIo> io;
  std::vector<std::uint8_t> fresh;
  CycleInputs in;
  bool follow = true;
  int count = 0;
  std::vector<CycleEvent> events;
  std::map<std::size_t, std::vector<std::vector<double>>> written;
};

TEST(Cycle, ASmoothMotionPlaysAfterTheStartRampAndEndsAtHome) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t j, double t) { return 0.3 * std::sin(2.0 * t + j); };
  bench.in.motion_duration_s = 1.0;
  bench.begin();
  bench.run_until(Phase::done);
  ASSERT_TRUE(bench.state.done());
  EXPECT_TRUE(bench.has(EventKind::motion_started));
  EXPECT_TRUE(bench.has(EventKind::motion_ended));
  EXPECT_FALSE(bench.state.end().fault);
  EXPECT_NEAR(bench.state.motion_time(), 1.0, 0.011);
  for (std::size_t b = 0; b < 2; ++b) {
    for (double goal : bench.written[b].back()) EXPECT_NEAR(goal, 0.0, 1e-3);
  }
}

TEST(Cycle, ANonFiniteTargetIsAMotionFaultThatHoldsTheJointAndRampsHome) {
  Bench bench(two_bus_model());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  bench.motion.fn = [nan](std::size_t j, double t) {
    if (j == 1 && t >= 0.3) return nan;
    return 0.5 * std::sin(3.0 * t);
  };
  bench.begin();
  bench.run_until(Phase::motion);
  bench.run_until(Phase::stop_ramp);
  const CycleEvent* fault = bench.first(EventKind::motion_fault);
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->joint, 1);
  EXPECT_TRUE(std::isnan(fault->value));
  EXPECT_TRUE(bench.state.end().fault);
  // From the cycle of the fault, joint 1 brakes from its last command: its
  // steps shrink, it never jumps toward anything.
  const auto& goals = bench.written[0];
  ASSERT_GE(goals.size(), 3u);
  const std::size_t k = goals.size() - 1;
  EXPECT_LE(std::abs(goals[k][1] - goals[k - 1][1]), std::abs(goals[k - 1][1] - goals[k - 2][1]));
  bench.run_until(Phase::done);
  ASSERT_TRUE(bench.state.done());
  for (const auto& cycle : bench.written[0]) {
    for (double goal : cycle) EXPECT_TRUE(std::isfinite(goal));
  }
  EXPECT_NEAR(bench.written[0].back()[1], 0.0, 1e-3);
}

TEST(Cycle, AnInfiniteTargetIsAMotionFaultToo) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t j, double t) {
    return j == 3 && t > 0.2 ? std::numeric_limits<double>::infinity() : 0.0;
  };
  bench.begin();
  bench.run_until(Phase::done);
  const CycleEvent* fault = bench.first(EventKind::motion_fault);
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->joint, 3);
}

// The goals a device receives: consecutive ones never further apart than one
// filter step at the velocity limit, however many cycles lie between them.
void expect_no_jump(const std::vector<std::vector<double>>& goals, double max_step) {
  for (std::size_t k = 1; k < goals.size(); ++k) {
    for (std::size_t d = 0; d < goals[k].size(); ++d) {
      EXPECT_LE(std::abs(goals[k][d] - goals[k - 1][d]), max_step + 1e-9)
          << "write " << k << " device " << d;
    }
  }
}

TEST(Cycle, ALateBusHoldsItsLastCommandAndResumesWithoutAJump) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t, double t) { return 1.2 * std::sin(1.5 * t); };
  bench.begin();
  bench.run_until(Phase::motion);
  std::vector<std::vector<double>> goals_b;
  for (int i = 0; i < 300; ++i) {
    // Bus b is late for 8 cycles out of every 20.
    bench.fresh[1] = (i % 20) < 12 ? 1 : 0;
    const CycleOutputs& out = bench.cycle();
    EXPECT_EQ(out.write[0], 1);
    EXPECT_EQ(out.write[1], bench.fresh[1]);
    if (out.write[1]) {
      goals_b.push_back(out.bus_commands[1]);
    }
  }
  ASSERT_GT(goals_b.size(), 100u);
  // The late bus's goals never jump (velocity limit 2 rad/s), and its joints
  // in the cycle state's own commands were held while it was late.
  expect_no_jump(goals_b, 2.0 / kRate);
  EXPECT_EQ(bench.state.late_cycles()[1], 120u);
  EXPECT_EQ(bench.state.late_cycles()[0], 0u);
  EXPECT_FALSE(bench.state.end().fault);
}

TEST(Cycle, ASilentDeviceIsFaultedAfterTheWatchdogAndTheOthersRampHome) {
  Bench bench(two_bus_model());
  bench.model.safety.watchdog_timeout_s = 0.1;
  bench.motion.fn = [](std::size_t, double t) { return 0.4 * std::sin(t); };
  bench.begin();
  bench.run_until(Phase::motion);
  const double silent_from = static_cast<double>(bench.count) / kRate;
  bench.health[1][0] = DeviceHealth::timeout;
  bench.run_until(Phase::stop_ramp, 100);
  const CycleEvent* fault = bench.first(EventKind::device_fault);
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->bus, 1u);
  EXPECT_EQ(fault->device, 0u);
  EXPECT_EQ(fault->joint, 2);
  // More than the watchdog after the last good answer (one cycle before).
  EXPECT_GE(fault->t - silent_from, 0.09 - 1e-9);
  EXPECT_LE(fault->t - silent_from, 0.1 + 0.02);
  EXPECT_TRUE(bench.state.joint_faulted(2));
  EXPECT_FALSE(bench.state.joint_faulted(3));
  bench.run_until(Phase::done);
  EXPECT_NEAR(bench.written[1].back()[1], 0.0, 1e-3);  // the healthy one went home
}

TEST(Cycle, AHardwareErrorFaultsTheDeviceAtOnce) {
  Bench bench(two_bus_model());
  bench.begin();
  bench.run_until(Phase::motion);
  bench.health[0][1] = DeviceHealth::hardware_error;
  bench.cycle();
  const CycleEvent* fault = bench.first(EventKind::device_fault);
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->health, DeviceHealth::hardware_error);
  EXPECT_EQ(bench.state.phase(), Phase::stop_ramp);
}

// The device's own error flag is its error bits: with `error_bits: warn`
// it is warned of once (its bits not being read) and plays on; with
// `ignore` nothing is said. Neither faults it.
TEST(Cycle, AHardwareErrorUnderErrorBitsWarnOrIgnoreIsNoFault) {
  for (const auto bits : {HealthLimits::Bits::warn, HealthLimits::Bits::ignore}) {
    Bench bench(two_bus_model());
    bench.model.buses[0].health.error_bits = bits;
    bench.begin();
    bench.run_until(Phase::motion);
    bench.health[0][1] = DeviceHealth::hardware_error;
    for (int i = 0; i < 50; ++i) bench.cycle();
    EXPECT_EQ(bench.first(EventKind::device_fault), nullptr);
    EXPECT_EQ(bench.state.phase(), Phase::motion);
    const CycleEvent* warning = bench.first(EventKind::health_warning);
    if (bits == HealthLimits::Bits::warn) {
      ASSERT_NE(warning, nullptr);
      EXPECT_EQ(warning->check, HealthCheck::error_bits);
      EXPECT_EQ(warning->device, 1u);
      int warnings = 0;
      for (const CycleEvent& e : bench.events) warnings += e.kind == EventKind::health_warning;
      EXPECT_EQ(warnings, 1);  // once per episode
    } else {
      EXPECT_EQ(warning, nullptr);
    }
  }
}

TEST(Cycle, ABusThatNeverComesBackIsFaultedOnlyAfterTenWatchdogs) {
  Bench bench(two_bus_model());
  bench.model.safety.watchdog_timeout_s = 0.1;
  bench.begin();
  bench.run_until(Phase::motion);
  const double late_from = static_cast<double>(bench.count) / kRate;
  bench.fresh[1] = 0;
  bench.run_until(Phase::stop_ramp, 300);
  const CycleEvent* fault = bench.first(EventKind::device_fault);
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->bus, 1u);
  EXPECT_GT(fault->t - late_from, 1.0 - 0.02);
  EXPECT_LT(fault->t - late_from, 1.0 + 0.03);
}

TEST(Cycle, ALongWatchdogCapsTheStuckBusGraceAtTwoSecondsMore) {
  RobotModel model = two_bus_model();
  model.safety.watchdog_timeout_s = 1.0;  // ten of them would be 10 s
  Bench bench(model);
  bench.begin();
  bench.run_until(Phase::motion);
  const double late_from = static_cast<double>(bench.count) / kRate;
  bench.fresh[0] = 0;
  bench.run_until(Phase::stop_ramp, 1000);
  const CycleEvent* fault = bench.first(EventKind::device_fault);
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->bus, 0u);
  EXPECT_GT(fault->t - late_from, 3.0 - 0.02);
  EXPECT_LT(fault->t - late_from, 3.0 + 0.03);
}

TEST(Cycle, AJointThatDoesNotFollowIsAFaultWithinTheWindow) {
  RobotModel model = two_bus_model();
  model.safety.following_error_window_s = 0.2;  // 20 cycles
  Bench bench(model);
  bench.motion.fn = [](std::size_t, double t) { return 0.5 * std::sin(2.0 * t); };
  bench.begin();
  bench.run_until(Phase::motion);
  // Device 1 of bus a reports another servo's position: 0.6 rad away.
  bench.follow = false;
  int over_cycles = 0;
  for (int i = 0; i < 200 && !bench.has(EventKind::following_error); ++i) {
    const CycleOutputs& out = bench.cycle();
    for (std::size_t b = 0; b < 2; ++b) bench.positions[b] = out.bus_commands[b];
    bench.positions[0][1] = out.bus_commands[0][1] + 0.6;
    ++over_cycles;
  }
  const CycleEvent* fault = bench.first(EventKind::following_error);
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->joint, 1);
  // RMS over 20 cycles of which k are 0.6 off: above 15 deg from k = 4.
  EXPECT_NEAR(fault->value, 0.6 * std::sqrt(4.0 / 20.0), 1e-6);
  EXPECT_EQ(over_cycles, 5);  // the error is seen the cycle after it is set
  EXPECT_TRUE(bench.state.end().fault);
  EXPECT_TRUE(bench.state.joint_faulted(1));
  EXPECT_EQ(bench.state.phase(), Phase::stop_ramp);
  EXPECT_EQ(bench.events.size(), 3u);  // started, following error, ended
}

TEST(Cycle, AnErrorBelowTheLimitOrABriefGlitchIsNoFault) {
  RobotModel model = two_bus_model();
  model.safety.following_error_window_s = 0.2;
  Bench bench(model);
  bench.in.motion_duration_s = 2.0;
  bench.begin();
  bench.follow = false;
  // Joint 0 never reaches home: the stop waits for it, then names it.
  for (int i = 0; i < 700 && !bench.state.done(); ++i) {
    const CycleOutputs& out = bench.cycle();
    for (std::size_t b = 0; b < 2; ++b) bench.positions[b] = out.bus_commands[b];
    bench.positions[0][0] += 0.25;                  // under 15 deg, always
    if (i % 50 == 0) bench.positions[1][0] += 1.0;  // 57 deg for a cycle now and then
  }
  EXPECT_TRUE(bench.state.done());
  EXPECT_FALSE(bench.has(EventKind::following_error));
  ASSERT_TRUE(bench.has(EventKind::stop_unreached));
  EXPECT_EQ(bench.first(EventKind::stop_unreached)->joint, 0);
  EXPECT_NEAR(bench.state.max_error(0), 0.25, 1e-6);
  EXPECT_NEAR(bench.state.max_error(2), 1.0, 1e-6);
}

TEST(Cycle, AStopThatRunsOverItsDeadlineCutsTorque) {
  RobotModel model = two_bus_model();
  model.limits[0].max_velocity = 0.05;  // 1.5 rad home at 0.05 rad/s: too slow to make it
  model.safety.stop_deadline_s = 3.0;
  model.safety.start_ramp_max_s = 1000.0;
  Bench bench(model);
  bench.motion.fn = [](std::size_t, double) { return 0.0; };
  bench.begin();
  bench.run_until(Phase::motion);
  // Jog joint 0 far from home, then stop.
  JogCommand jog{0, 1.4};
  bench.in.jog = &jog;
  bench.cycle();
  bench.in.jog = nullptr;
  for (int i = 0; i < 3000; ++i) bench.cycle();
  EXPECT_GT(bench.written[0].back()[0], 1.0);  // the jog went through the filter
  bench.in.stop = true;
  const double stop_at = static_cast<double>(bench.count) / kRate;
  bench.run_until(Phase::done);
  const CycleEvent* cut = bench.first(EventKind::stop_deadline);
  ASSERT_NE(cut, nullptr);
  EXPECT_NEAR(cut->t - stop_at, 3.0, 0.011);
  EXPECT_TRUE(bench.state.end().torque_cut);
  EXPECT_TRUE(bench.state.end().stopped);
}

TEST(Cycle, AnAbortCutsTorqueAtOnce) {
  Bench bench(two_bus_model());
  bench.begin();
  bench.run_until(Phase::motion);
  bench.in.stop = true;
  bench.cycle();
  EXPECT_EQ(bench.state.phase(), Phase::stop_ramp);
  bench.in.abort = true;
  const CycleOutputs& out = bench.cycle();
  EXPECT_TRUE(out.torque_off_now);
  EXPECT_TRUE(bench.state.done());
  EXPECT_TRUE(bench.has(EventKind::aborted));
}

// Servos slower than the filter may command: each travels toward its last
// goal at `speed` over the run's time, stalls of the loop included, and stops
// short of `floor` (a blocked joint) where one is set.
struct SlowServos {
  explicit SlowServos(Bench& b) : bench(b), goals(b.positions) { bench.follow = false; }
  // One cycle at the bench's time; returns the largest step of a command.
  double cycle() {
    const double now = static_cast<double>(bench.count) / kRate;
    const double reach = speed * (now - last);
    last = now;
    for (std::size_t b = 0; b < goals.size(); ++b) {
      for (std::size_t d = 0; d < goals[b].size(); ++d) {
        double& p = bench.positions[b][d];
        p += std::clamp(goals[b][d] - p, -reach, reach);
        p = std::max(p, floor[b][d]);
      }
    }
    const CycleOutputs& out = bench.cycle();
    double step = 0.0;
    for (std::size_t b = 0; b < goals.size(); ++b) {
      if (!out.write[b]) continue;
      for (std::size_t d = 0; d < goals[b].size(); ++d) {
        step = std::max(step, std::abs(out.bus_commands[b][d] - goals[b][d]));
      }
      goals[b] = out.bus_commands[b];
    }
    return step;
  }

  Bench& bench;
  std::vector<std::vector<double>> goals;
  std::vector<std::vector<double>> floor{{-9.0, -9.0}, {-9.0, -9.0}};
  double speed = 1.0;  // rad/s: keeps up with the ramps, not with the filter's 2 rad/s
  double last = 0.0;
};

TEST(Cycle, AStallDuringTheStopRampKeepsTorqueOnUntilTheServosAreHome) {
  RobotModel model = two_bus_model();
  model.safety.start_ramp_s = 1.0;
  model.safety.stop_ramp_s = 1.0;
  Bench bench(model);
  bench.motion.fn = [](std::size_t, double) { return 0.4; };
  bench.in.motion_duration_s = 0.5;
  bench.begin();
  SlowServos servos(bench);
  double largest_step = 0.0;
  bool stalled = false;
  while (!bench.state.done() && bench.count < 2000) {
    largest_step = std::max(largest_step, servos.cycle());
    const CycleEvent* ended = bench.first(EventKind::motion_ended);
    if (!stalled && ended && static_cast<double>(bench.count) / kRate >= ended->t + 0.1) {
      bench.count += 80;  // the loop stalls 0.8 s: most of the ramp's time passes at once
      stalled = true;
    }
  }
  ASSERT_TRUE(stalled);
  ASSERT_TRUE(bench.state.done());
  EXPECT_FALSE(bench.state.end().fault);
  // The command never jumped, and torque went off with every servo home.
  EXPECT_LE(largest_step, model.limits[0].max_velocity / kRate + 1e-9);
  for (std::size_t j = 0; j < 4; ++j) {
    EXPECT_NEAR(bench.state.measured()[j], 0.0, 0.05) << "joint " << j;
  }
  EXPECT_FALSE(bench.has(EventKind::stop_unreached));
}

TEST(Cycle, AJointThatNeverArrivesEndsTheStopABoundedTimeAfterTheRampAndIsNamed) {
  RobotModel model = two_bus_model();
  model.safety.start_ramp_s = 1.0;
  model.safety.stop_ramp_s = 1.0;
  Bench bench(model);
  bench.motion.fn = [](std::size_t, double) { return 0.4; };
  bench.in.motion_duration_s = 0.5;
  bench.begin();
  SlowServos servos(bench);
  servos.floor[1][1] = 0.1;  // joint 3 is blocked 0.1 rad short of home
  while (!bench.state.done() && bench.count < 2000) servos.cycle();
  ASSERT_TRUE(bench.state.done());
  const CycleEvent* ended = bench.first(EventKind::motion_ended);
  const CycleEvent* unreached = bench.first(EventKind::stop_unreached);
  ASSERT_NE(ended, nullptr);
  ASSERT_NE(unreached, nullptr);
  EXPECT_EQ(unreached->joint, 3);
  EXPECT_NEAR(unreached->value, 0.1, 1e-9);
  EXPECT_NEAR(unreached->t - ended->t, 1.0 + kStopSettleTime, 0.011);
  int named = 0;
  for (const CycleEvent& e : bench.events) named += e.kind == EventKind::stop_unreached ? 1 : 0;
  EXPECT_EQ(named, 1);
  EXPECT_FALSE(bench.has(EventKind::stop_deadline));
}

TEST(Cycle, TheWaitForAJointEndsBeforeTheStopDeadlineWouldCutTorque) {
  RobotModel model = two_bus_model();
  model.safety.start_ramp_s = 1.0;
  model.safety.stop_ramp_s = 1.0;
  model.safety.stop_deadline_s = 2.0;  // under the ramp and the whole wait
  Bench bench(model);
  bench.motion.fn = [](std::size_t, double) { return 0.4; };
  bench.in.motion_duration_s = 0.5;
  bench.begin();
  SlowServos servos(bench);
  servos.floor[0][0] = 0.1;
  while (!bench.state.done() && bench.count < 2000) servos.cycle();
  const CycleEvent* ended = bench.first(EventKind::motion_ended);
  const CycleEvent* unreached = bench.first(EventKind::stop_unreached);
  ASSERT_NE(ended, nullptr);
  ASSERT_NE(unreached, nullptr);
  EXPECT_EQ(unreached->joint, 0);
  EXPECT_LT(unreached->t - ended->t, 2.0);
  EXPECT_FALSE(bench.has(EventKind::stop_deadline));
  EXPECT_FALSE(bench.state.end().torque_cut);
}

// A source that winds down at a stop keeps playing (here its joints keep
// moving at 0.4 rad/s) for the time it asked for; the ramp home follows, and
// the motion ended at the request.
TEST(Cycle, AStopRequestLetsTheMotionWindDownBeforeTheRampHome) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t, double t) { return 0.4 * t; };
  bench.motion.wind = 0.6;
  bench.begin();
  bench.run_until(Phase::motion);
  for (int i = 0; i < 50; ++i) bench.cycle();
  bench.in.stop = true;
  const double asked = static_cast<double>(bench.count) / kRate;
  bench.cycle();
  bench.in.stop = false;
  ASSERT_EQ(bench.motion.wound_at.size(), 1u);
  EXPECT_NEAR(bench.motion.wound_at[0], asked - bench.state.motion_start(), 1e-9);
  EXPECT_NEAR(bench.first(EventKind::motion_ended)->t, asked, 1e-9);
  EXPECT_EQ(bench.state.phase(), Phase::stop_ramp);
  EXPECT_TRUE(bench.state.winding_down());
  while (bench.state.winding_down() && bench.count < 1000) bench.cycle();
  const double ramp_start = static_cast<double>(bench.count - 1) / kRate;
  EXPECT_NEAR(ramp_start - asked, 0.6, 0.011);
  // The motion played to the end of its wind-down, 0.6 s after the request.
  EXPECT_NEAR(bench.state.measured()[0], 0.4 * (bench.motion.wound_at[0] + 0.6), 0.01);
  bench.run_until(Phase::done);
  EXPECT_TRUE(bench.state.end().stopped);
  EXPECT_FALSE(bench.state.end().fault);
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(bench.state.measured()[j], 0.0, 1e-9);
  EXPECT_EQ(bench.motion.wound_at.size(), 1u);
}

// A fault never waits for a wind-down: before one it ramps home at once,
// and during one it ends it.
TEST(Cycle, AFaultRampsHomeAtOnceWindingDownOrNot) {
  for (const bool during : {false, true}) {
    Bench bench(two_bus_model());
    bench.motion.fn = [](std::size_t, double t) { return 0.4 * t; };
    bench.motion.wind = 1.0;
    bench.begin();
    bench.run_until(Phase::motion);
    for (int i = 0; i < 20; ++i) bench.cycle();
    if (during) {
      bench.in.stop = true;
      bench.cycle();
      bench.in.stop = false;
      for (int i = 0; i < 10; ++i) bench.cycle();
      ASSERT_TRUE(bench.state.winding_down());
    }
    bench.health[0][1] = DeviceHealth::hardware_error;
    bench.cycle();
    ASSERT_TRUE(bench.has(EventKind::device_fault));
    EXPECT_EQ(bench.state.phase(), Phase::stop_ramp) << during;
    EXPECT_FALSE(bench.state.winding_down()) << during;
    EXPECT_EQ(bench.motion.wound_at.size(), during ? 1u : 0u);
    bench.run_until(Phase::done);
    EXPECT_TRUE(bench.state.end().fault);
    EXPECT_NEAR(bench.state.measured()[0], 0.0, 1e-9) << during;
  }
}

// A second stop (an abort) during a wind-down cuts torque at once, as
// during a ramp.
TEST(Cycle, AnAbortDuringAWindDownCutsTorqueAtOnce) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t, double t) { return 0.4 * t; };
  bench.motion.wind = 1.0;
  bench.begin();
  bench.run_until(Phase::motion);
  for (int i = 0; i < 20; ++i) bench.cycle();
  bench.in.stop = true;
  for (int i = 0; i < 10; ++i) bench.cycle();
  ASSERT_TRUE(bench.state.winding_down());
  bench.in.abort = true;
  const CycleOutputs& out = bench.cycle();
  EXPECT_TRUE(out.torque_off_now);
  EXPECT_TRUE(bench.state.done());
  EXPECT_FALSE(bench.state.winding_down());
  EXPECT_TRUE(bench.state.end().torque_cut);
  EXPECT_TRUE(bench.has(EventKind::aborted));
}

// However long a source asks to wind down, the stop leaves its ramp and the
// wait for the joints their time before the deadline, which counts from
// the request: the stop ends on time, without a torque cut.
TEST(Cycle, AWindDownIsCutShortToFitTheStopDeadline) {
  RobotModel model = two_bus_model();
  model.safety.stop_deadline_s = 3.0;
  Bench bench(model);
  bench.motion.fn = [](std::size_t, double t) { return 0.4 * t; };
  bench.motion.wind = 100.0;
  bench.in.motion_duration_s = 0.5;
  bench.begin();
  bench.run_until(Phase::motion);
  bench.run_until(Phase::stop_ramp);
  const double asked = bench.first(EventKind::motion_ended)->t;
  while (bench.state.winding_down() && bench.count < 2000) bench.cycle();
  const double ramp_start = static_cast<double>(bench.count - 1) / kRate;
  EXPECT_NEAR(ramp_start - asked, 3.0 - 0.5 - kStopSettleTime, 0.011);
  bench.run_until(Phase::done);
  EXPECT_FALSE(bench.state.end().torque_cut);
  EXPECT_FALSE(bench.has(EventKind::stop_deadline));
  EXPECT_LT(static_cast<double>(bench.count) / kRate - asked, 3.0);
}

// The motion is told the time the stop deadline leaves it (the deadline
// less the ramp, the wait for the joints and a cycle), so it can come to
// rest within it.
TEST(Cycle, AStopGrantsTheMotionTheTimeItsDeadlineLeaves) {
  RobotModel model = two_bus_model();
  model.safety.stop_deadline_s = 4.0;
  Bench bench(model);
  bench.motion.wind = 0.2;
  bench.in.motion_duration_s = 0.5;
  bench.begin();
  bench.run_until(Phase::done);
  ASSERT_EQ(bench.motion.granted.size(), 1u);
  EXPECT_NEAR(bench.motion.granted[0], 4.0 - 0.5 - kStopSettleTime - 1.0 / kRate, 1e-12);
  // No time left for a wind-down: the motion is not asked, the ramp starts at once.
  model.safety.stop_deadline_s = 0.5 + kStopSettleTime;
  Bench tight(model);
  tight.motion.wind = 0.2;
  tight.in.motion_duration_s = 0.5;
  tight.begin();
  tight.run_until(Phase::done);
  EXPECT_TRUE(tight.motion.granted.empty());
  EXPECT_FALSE(tight.state.end().torque_cut);
}

// A walk whose two strides (2 s at 1 Hz) do not fit the stop deadline
// (3 s: 0.49 s are left after the 0.5 s ramp and the 2 s wait) winds down
// in the time granted, completely: it stands when the ramp home begins,
// and the stop ends inside its deadline.
TEST(Cycle, AWalkWoundDownInTheTimeGrantedStandsWhenTheRampBegins) {
  RobotModel model = two_bus_model();
  model.safety.stop_deadline_s = 3.0;
  Bench bench(model);
  const std::string path = ::testing::TempDir() + "/cycle_walk.yaml";
  std::ofstream(path) << "name: walk\nstride_frequency_hz: 1.0\n"
                         "curves: {swing: \"5 + 10*sin(2*PI*t)\"}\n"
                         "limbs: {a: 0.0, b: 0.25, c: 0.5, d: 0.75}\n"
                         "joints:\n  j0: {curve: swing, limb: a}\n  j1: {curve: swing, limb: b}\n"
                         "  j2: {curve: swing, limb: c}\n  j3: {curve: swing, limb: d}\n";
  std::vector<JointSpec> joints(4);
  for (std::size_t j = 0; j < 4; ++j) {
    joints[j].name = "j" + std::to_string(j);
    joints[j].limits = model.limits[j];
  }
  bench.show = load_gait_source(path, joints);
  bench.in.motion_duration_s = 1.3;  // mid-stride
  bench.begin();
  bench.run_until(Phase::stop_ramp);
  ASSERT_TRUE(bench.state.winding_down());
  const double asked = bench.first(EventKind::motion_ended)->t;
  while (bench.state.winding_down() && bench.count < 2000) bench.cycle();
  const double ramp_start = static_cast<double>(bench.count - 1) / kRate;
  EXPECT_NEAR(ramp_start - asked, 3.0 - 0.5 - kStopSettleTime - 1.0 / kRate, 0.011);
  // The walk stands (each joint at its stride mean, 5 deg, and still) from
  // the end of the time granted on.
  const double granted_end = ramp_start - bench.state.motion_start();
  for (const double after : {0.0, 0.1, 1.0}) {
    std::vector<double> pose(4, 0.0);
    bench.show->sample(granted_end + after, pose);
    for (std::size_t j = 0; j < 4; ++j) {
      EXPECT_NEAR(pose[j], deg_to_rad(5.0), 1e-9) << "joint " << j << ", " << after << " s after";
    }
  }
  // What the figure was sent as the ramp began: near the stand already.
  for (std::size_t j = 0; j < 4; ++j) {
    EXPECT_NEAR(bench.state.measured()[j], deg_to_rad(5.0), deg_to_rad(0.5)) << "joint " << j;
  }
  bench.run_until(Phase::done);
  EXPECT_FALSE(bench.state.end().torque_cut);
  EXPECT_FALSE(bench.has(EventKind::stop_deadline));
  EXPECT_FALSE(bench.has(EventKind::stop_unreached));
  EXPECT_LT(static_cast<double>(bench.count - 1) / kRate - asked, 3.0);
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(bench.state.measured()[j], 0.0, 1e-9);
}

TEST(Cycle, SteeringReachesTheMotionSourceAtTheStartOfTheCycle) {
  Bench bench(two_bus_model());
  bench.begin();
  MotionCommand command{0.25, -0.5};
  bench.in.steer = &command;
  bench.cycle();
  EXPECT_EQ(bench.motion.steered.speed_m_s, 0.25);
  EXPECT_EQ(bench.motion.steered.turn_rad_s, -0.5);
}

TEST(Cycle, ManualModeHoldsTheJointsMovesThemToClampedTargetsAndReturnsSmoothly) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t j, double t) { return 0.5 * std::sin(3.0 * t + j); };
  bench.begin();
  bench.run_until(Phase::motion);
  for (int i = 0; i < 30; ++i) bench.cycle();
  const double max_step = bench.model.limits[0].max_velocity / kRate + 1e-9;
  std::vector<double> last(bench.state.measured().begin(), bench.state.measured().end());
  auto check_step = [&](const CycleOutputs& out) {
    for (std::size_t j = 0; j < 4; ++j) {
      EXPECT_LE(std::abs(out.commands[j] - last[j]), max_step) << "joint " << j;
      last[j] = out.commands[j];
    }
  };
  for (std::size_t j = 0; j < 4; ++j) last[j] = bench.written[j / 2].back()[j % 2];

  // On: the joints come to rest where they were, whatever the motion asks.
  bench.in.manual = true;
  const CycleOutputs& first = bench.cycle();
  check_step(first);
  EXPECT_TRUE(bench.state.manual());
  const std::vector<double> held(bench.state.manual_pose().begin(),
                                 bench.state.manual_pose().end());
  for (int i = 0; i < 100; ++i) check_step(bench.cycle());
  for (std::size_t j = 0; j < 4; ++j) {
    EXPECT_NEAR(last[j], held[j], 1e-6) << "joint " << j;
  }

  // A target beyond the limit stops at the limit; another joint's target,
  // sent in the same cycle, arrives too.
  const ManualTarget targets[2] = {{0, 10.0}, {3, -0.4}};
  bench.in.manual_targets = targets;
  check_step(bench.cycle());
  bench.in.manual_targets = {};
  EXPECT_EQ(bench.state.manual_pose()[0], bench.model.limits[0].max_position);
  for (int i = 0; i < 300; ++i) {
    check_step(bench.cycle());
    EXPECT_LE(last[0], bench.model.limits[0].max_position);
  }
  EXPECT_NEAR(last[0], bench.model.limits[0].max_position, 1e-6);
  EXPECT_NEAR(last[3], -0.4, 1e-6);
  EXPECT_NEAR(last[1], held[1], 1e-6);

  // Off: back to the motion, through the filter.
  bench.in.manual = false;
  for (int i = 0; i < 300; ++i) check_step(bench.cycle());
  EXPECT_FALSE(bench.state.manual());
  for (std::size_t j = 0; j < 4; ++j) {
    EXPECT_NEAR(last[j], bench.motion.fn(j, bench.in.t - bench.state.motion_start()), 1e-6);
  }
}

TEST(Cycle, ManualTargetsOutsideTheMotionPhaseAreIgnored) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t, double) { return 0.3; };
  bench.begin();
  bench.in.manual = true;
  const ManualTarget target{1, -1.0};
  bench.in.manual_targets = std::span<const ManualTarget>(&target, 1);
  // The start ramp goes to the first pose regardless.
  while (bench.state.phase() == Phase::start_ramp) {
    EXPECT_FALSE(bench.state.manual());
    bench.cycle();
  }
  const auto& goals = bench.written[0];
  ASSERT_GE(goals.size(), 2u);
  EXPECT_NEAR(goals[goals.size() - 2][1], 0.3, 1e-2);
  // In the motion phase the same input takes effect.
  EXPECT_TRUE(bench.state.manual());
  EXPECT_EQ(bench.state.manual_pose()[1], -1.0);
  bench.in.manual_targets = {};
  // A stop ends manual mode: the stop ramp goes home.
  bench.in.stop = true;
  bench.run_until(Phase::done);
  EXPECT_FALSE(bench.state.manual());
  for (double goal : bench.written[0].back()) EXPECT_NEAR(goal, 0.0, 1e-3);
}

// A non-looping 4 s show on joint 0 of the two-bus model: a ramp from 0 to
// 40 deg over 2 s (0.35 rad/s), then held.
std::unique_ptr<MotionSource> ramp_show(const RobotModel& model) {
  std::vector<JointSpec> joints;
  for (std::size_t j = 0; j < model.joint_count(); ++j) {
    joints.push_back(JointSpec{model.joint_names[j], model.limits[j], 0.0, JointType::revolute});
  }
  ShowFile show;
  show.name = "ramp";
  show.duration_s = 4.0;
  ShowTrack track;
  track.joint = "j0";
  track.keys = {ShowKey{0.0, 0.0, Interpolation::linear, {}},
                ShowKey{2.0, 40.0, Interpolation::linear, {}}};
  show.tracks.push_back(track);
  return make_show_source(show, joints);
}

double ramp_show_value(double show_t) {
  return deg_to_rad(40.0) * std::clamp(show_t, 0.0, 2.0) / 2.0;
}

// Joint 0's commands never change velocity by more than its acceleration
// limit allows (nor move faster than its velocity limit) from cycle to cycle.
struct SmoothCheck {
  explicit SmoothCheck(const RobotModel& model) : limits(model.limits[0]), dt(model.dt) {}
  void add(double command) {
    if (have_last) {
      const double v = (command - last) / dt;
      EXPECT_LE(std::abs(v), limits.max_velocity + 1e-6);
      if (have_v) {
        EXPECT_LE(std::abs(v - last_v), limits.max_acceleration * dt + 1e-6);
      }
      last_v = v;
      have_v = true;
    }
    last = command;
    have_last = true;
  }
  JointLimits limits;
  double dt;
  double last = 0.0, last_v = 0.0;
  bool have_last = false, have_v = false;
};

TEST(Cycle, APausedShowHoldsItsPoseAndPlayResumesFromThere) {
  Bench bench(two_bus_model());
  bench.show = ramp_show(bench.model);
  bench.begin();
  bench.run_until(Phase::motion);
  SmoothCheck smooth(bench.model);
  for (int i = 0; i < 50; ++i) smooth.add(bench.cycle().commands[0]);
  EXPECT_TRUE(bench.state.show().show);
  EXPECT_TRUE(bench.state.show().playing);
  EXPECT_EQ(bench.state.show().duration_s, 4.0);
  const double paused_at = bench.state.show().position_s;
  EXPECT_NEAR(paused_at, bench.in.t - bench.state.motion_start(), 1e-9);

  // Pause: the show's time stops; the joint comes to rest at its pose then.
  ShowCommand command{false, 0, 0.0};
  bench.in.show = &command;
  smooth.add(bench.cycle().commands[0]);
  bench.in.show = nullptr;
  for (int i = 0; i < 100; ++i) {
    smooth.add(bench.cycle().commands[0]);
    EXPECT_FALSE(bench.state.show().playing);
    EXPECT_NEAR(bench.state.show().position_s, paused_at + 1.0 / kRate, 1e-9);
  }
  EXPECT_NEAR(smooth.last, ramp_show_value(paused_at + 1.0 / kRate), 1e-6);
  EXPECT_NEAR(bench.state.command_velocity()[0], 0.0, 1e-6);

  // Play: on from the same show time, one cycle per cycle.
  command.playing = true;
  bench.in.show = &command;
  smooth.add(bench.cycle().commands[0]);
  bench.in.show = nullptr;
  for (int i = 0; i < 60; ++i) smooth.add(bench.cycle().commands[0]);
  EXPECT_TRUE(bench.state.show().playing);
  EXPECT_NEAR(bench.state.show().position_s, paused_at + 1.0 / kRate + 60.0 / kRate, 1e-9);
  EXPECT_NEAR(smooth.last, ramp_show_value(bench.state.show().position_s), 1e-6);
}

TEST(Cycle, ASeekMovesTheShowsTimeAndTheFilterRampsToThePose) {
  Bench bench(two_bus_model());
  bench.show = ramp_show(bench.model);
  bench.begin();
  bench.run_until(Phase::motion);
  SmoothCheck smooth(bench.model);
  for (int i = 0; i < 20; ++i) smooth.add(bench.cycle().commands[0]);

  // Ahead, past the ramp's end (beyond the show: clamped to its end).
  ShowCommand command{true, 1, 9.0};
  bench.in.show = &command;
  smooth.add(bench.cycle().commands[0]);
  bench.in.show = nullptr;
  EXPECT_EQ(bench.state.show().position_s, 4.0);
  EXPECT_FALSE(bench.state.show().playing);  // a non-looping show at its end
  for (int i = 0; i < 200; ++i) smooth.add(bench.cycle().commands[0]);
  EXPECT_NEAR(smooth.last, deg_to_rad(40.0), 1e-6);

  // Back to 1 s while paused: the show stays paused there.
  command = ShowCommand{false, 2, 1.0};
  bench.in.show = &command;
  smooth.add(bench.cycle().commands[0]);
  bench.in.show = nullptr;
  for (int i = 0; i < 200; ++i) smooth.add(bench.cycle().commands[0]);
  EXPECT_FALSE(bench.state.show().playing);
  EXPECT_EQ(bench.state.show().position_s, 1.0);
  EXPECT_NEAR(smooth.last, ramp_show_value(1.0), 1e-6);

  // The same command again (no new seek) plays on from there.
  command.playing = true;
  bench.in.show = &command;
  bench.cycle();
  bench.in.show = nullptr;
  EXPECT_TRUE(bench.state.show().playing);
  EXPECT_NEAR(bench.state.show().position_s, 1.0, 1e-9);
}

TEST(Cycle, ShowCommandsOutsideTheMotionPhaseAreIgnored) {
  Bench bench(two_bus_model());
  bench.show = ramp_show(bench.model);
  bench.begin();
  const ShowCommand command{false, 1, 3.0};
  bench.in.show = &command;
  EXPECT_FALSE(bench.cycle().show_controlled);  // nothing for a sound track to follow
  bench.in.show = nullptr;
  bench.run_until(Phase::motion);
  EXPECT_FALSE(bench.cycle().show_controlled);
  EXPECT_TRUE(bench.state.show().playing);
  EXPECT_NEAR(bench.state.show().position_s, 1.0 / kRate, 1e-9);
  // In the motion phase the command acts, and the cycle says so.
  bench.in.show = &command;
  EXPECT_TRUE(bench.cycle().show_controlled);
  bench.in.show = nullptr;
  EXPECT_FALSE(bench.cycle().show_controlled);
  EXPECT_FALSE(bench.state.show().playing);
  EXPECT_EQ(bench.state.show().position_s, 3.0);
}

TEST(Cycle, StepDoesNotAllocate) {
  Bench bench(two_bus_model());
  bench.motion.fn = [](std::size_t j, double t) {
    return j == 2 && t > 1.0 ? std::numeric_limits<double>::quiet_NaN() : std::sin(t);
  };
  bench.begin();
  std::vector<BusIo> io(2);
  for (std::size_t b = 0; b < 2; ++b) io[b] = BusIo{true, bench.positions[b], bench.health[b]};
  bench.in.buses = io;
  test::AllocationCounter counter;
  for (int i = 0; i < 600 && !bench.state.done(); ++i) {
    bench.in.t = i / kRate;
    io[1].fresh = i % 7 != 0;
    bench.in.manual = i > 150 && i < 250;  // manual mode on and off on the way
    const ManualTarget target{0, 0.1 * (i % 5)};
    bench.in.manual_targets = std::span<const ManualTarget>(&target, 1);
    step(bench.model, bench.motion, bench.state, bench.in);
  }
  EXPECT_EQ(counter.count(), 0);
  EXPECT_TRUE(bench.state.end().fault);  // the NaN path ran
}

TEST(Cycle, AShowsTransportDoesNotAllocate) {
  Bench bench(two_bus_model());
  bench.show = ramp_show(bench.model);
  // step() is called directly (Bench::cycle() records, and so allocates):
  // the devices stay where they are, which is no fault here.
  bench.model.following_error.assign(bench.model.joint_count(), 1e9);
  bench.begin();
  bench.run_until(Phase::motion);
  test::AllocationCounter counter;
  ShowCommand command;
  for (int i = 0; i < 300; ++i) {
    command.playing = (i / 40) % 2 == 0;
    if (i % 25 == 0) command = ShowCommand{command.playing, command.seeks + 1, 0.01 * i};
    bench.in.show = i % 5 == 0 ? &command : nullptr;
    step(bench.model, bench.source(), bench.state, bench.in);
    bench.in.t += 1.0 / kRate;
  }
  bench.in.show = nullptr;
  EXPECT_EQ(counter.count(), 0);
  ASSERT_EQ(bench.state.phase(), Phase::motion);
  // Sought to 2.75 s while playing (cycle 275), paused five cycles later.
  EXPECT_NEAR(bench.state.show().position_s, 2.80, 1e-9);
}

TEST(NextDeadline, CountsOverrunsAndSkipsWholeMissedCycles) {
  const Nanos period = 5'000'000;
  NextDeadline on_time = next_deadline(0, 3'000'000, period);
  EXPECT_EQ(on_time.deadline, period);
  EXPECT_FALSE(on_time.overrun);
  NextDeadline late = next_deadline(0, 6'000'000, period);
  EXPECT_TRUE(late.overrun);
  EXPECT_EQ(late.skipped, 0u);
  EXPECT_EQ(late.deadline, period);
  NextDeadline very_late = next_deadline(0, 23'000'000, period);
  EXPECT_TRUE(very_late.overrun);
  EXPECT_EQ(very_late.skipped, 3u);
  EXPECT_EQ(very_late.deadline, 20'000'000);
  EXPECT_GT(very_late.deadline + period, 23'000'000);
}

}  // namespace
}  // namespace animrt
