// The late-bus path on the wall clock (not lockstep): the quadruped's
// simulated Dynamixel bus is late on some cycles, and the goals the servos
// receive must stay continuous. A late bus is made on the loop's side: the
// rig's WatchedBus holds the I/O thread before a read (the answers come
// late) or before a write (the Sync Write goes out late), as a congested
// adapter would. The goals are sampled on the device side: the simulated
// servos hand every goal they accept to a physics model, and this one logs
// them with the wall time they arrived. Joints are driven faster than their
// velocity limit, so the safety filter moves them at that limit.
//
// Checks: consecutive goals of a joint, as received, differ by at most the
// joint's velocity limit times the time between them plus one cycle of
// motion (a goal may arrive late by scheduling; the next one is then close
// behind it) and two ticks of quantisation; late cycles were counted where
// lateness was forced; a bus late for less than the watchdog's grace
// (late_bus_grace, runtime/src/cycle.cpp) does not fault, one stuck for
// longer faults only after it. No timing is asserted.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "animrt/sim/dynamixel_servo.hpp"
#include "animrt/sim/joint_physics.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

using test::BusCall;
using test::SimRig;

const std::string kQuadruped = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";
constexpr double kWatchdogS = 0.5;  // the runtime's (safety.watchdog_timeout_s), see Rig

// Every joint swings +-35 deg at 2 Hz: 440 deg/s at the peak, above every
// joint's 300 deg/s limit.
class FastSway final : public MotionSource {
 public:
  explicit FastSway(std::size_t joints) {
    for (std::size_t j = 0; j < joints; ++j) driven_.push_back(static_cast<int>(j));
  }
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override {
    const double sway = 35.0 * std::numbers::pi / 180.0 * std::sin(2 * std::numbers::pi * 2.0 * t);
    for (std::size_t j = 0; j < targets.size(); ++j) targets[j] = (j % 2 ? -sway : sway);
  }

 private:
  std::vector<int> driven_;
};

// The motor of every servo, logging each goal it is handed with the wall
// time it arrived. A rate limiter at twice the joints' velocity limit.
class GoalLog final : public sim::JointPhysics {
 public:
  struct Goal {
    Nanos at;
    double rad;
    bool torque;
  };
  explicit GoalLog(const RobotConfig& config) {
    for (const auto& joint : config.joints) {
      names_.push_back(joint.name);
      limits_.push_back(joint.limits.max_velocity);
    }
    const std::size_t n = names_.size();
    position_.assign(n, 0.0);
    velocity_.assign(n, 0.0);
    goal_.assign(n, 0.0);
    torque_.assign(n, 0);
    log_.resize(n);
    for (auto& l : log_) l.reserve(kCapacity);
  }
  int joint_index(const std::string& joint) const override {
    for (std::size_t j = 0; j < names_.size(); ++j) {
      if (names_[j] == joint) return static_cast<int>(j);
    }
    return -1;
  }
  void advance(Nanos now) override {
    std::lock_guard lock(mutex_);
    if (last_ < 0 || now <= last_) {
      last_ = std::max(last_, now);
      return;
    }
    const double dt = to_seconds(now - last_);
    last_ = now;
    for (std::size_t j = 0; j < position_.size(); ++j) {
      if (!torque_[j]) {
        velocity_[j] = 0.0;
        continue;
      }
      const double step =
          std::clamp(goal_[j] - position_[j], -2 * limits_[j] * dt, 2 * limits_[j] * dt);
      position_[j] += step;
      velocity_[j] = step / dt;
    }
  }
  void command(int index, double goal_rad, bool torque_on) override {
    std::lock_guard lock(mutex_);
    const auto j = static_cast<std::size_t>(index);
    goal_[j] = goal_rad;
    torque_[j] = torque_on ? 1 : 0;
    if (log_[j].size() < kCapacity) log_[j].push_back(Goal{wall_.now(), goal_rad, torque_on});
  }
  double position(int index) const override {
    std::lock_guard lock(mutex_);
    return position_[static_cast<std::size_t>(index)];
  }
  double velocity(int index) const override {
    std::lock_guard lock(mutex_);
    return velocity_[static_cast<std::size_t>(index)];
  }

  // Goals received by joint `j` (read after the run).
  const std::vector<Goal>& goals(std::size_t j) const { return log_[j]; }
  const std::string& name(std::size_t j) const { return names_[j]; }
  std::size_t joints() const { return names_.size(); }
  double limit(std::size_t j) const { return limits_[j]; }

 private:
  static constexpr std::size_t kCapacity = 1 << 14;
  mutable std::mutex mutex_;
  MonotonicClock wall_;
  Nanos last_ = -1;
  std::vector<std::string> names_;
  std::vector<double> limits_, position_, velocity_, goal_;
  std::vector<std::uint8_t> torque_;
  std::vector<std::vector<Goal>> log_;
};

struct Rig {
  std::unique_ptr<GoalLog> physics;
  std::unique_ptr<SimRig> rig;
  double period_s = 0.0;

  Rig() {
    // The physics needs the joints before the devices start: load once for them.
    const RobotConfig config = load_robot(kQuadruped).config;
    physics = std::make_unique<GoalLog>(config);
    test::RigSettings settings;
    settings.lockstep = false;
    // On the wall clock a loaded machine (two tests at a time beside a
    // build) holds the simulator up now and then: with the shipped 0.1 s
    // watchdog and 50 ms timeouts a pause of 0.1 s faulted servos the
    // tests did not make late. The lateness the tests make is measured
    // against these: several times the watchdog, inside or beyond the
    // grace (late_bus_grace, runtime/src/cycle.cpp: 2.5 s here).
    settings.min_bus_timeout_s = 0.25;
    settings.physics = physics.get();
    settings.edit = [](RobotConfig& c) {
      c.safety.start_ramp_s = 0.3;
      c.safety.stop_ramp_s = 0.3;
      c.safety.watchdog_timeout_s = kWatchdogS;
    };
    settings.edit_motion = [](LoadedRobot& r) {
      r.motion = std::make_unique<FastSway>(r.config.joints.size());
    };
    rig = std::make_unique<SimRig>(kQuadruped, settings);
    period_s = 1.0 / rig->config().rate_hz;
  }
  ~Rig() { rig.reset(); }  // the devices stop before their physics goes

  // Holds the bus I/O thread for `hold` before every `every`-th call of kind
  // `call` from the `from`-th on (only in cycles: after activation).
  void make_late(BusCall call, std::uint64_t from, std::uint64_t every,
                 std::chrono::milliseconds hold) {
    rig->on_bus_call = [=, this](std::size_t, BusCall c, std::uint64_t index) {
      if (c == BusCall::activate) active_ = true;
      if (c != call || !active_) return;
      if (index >= from && (index - from) % every == 0) {
        std::this_thread::sleep_for(hold);
        ++held;
      }
    };
  }
  std::atomic<int> held{0};

  // Every pair of consecutive goals a joint received with torque on: at most
  // one cycle of motion at the velocity limit apart, however long the bus
  // was late in between (its joints hold while it is late). A runner that
  // sent a late bus the current command would move it several cycles at once.
  void expect_continuous_goals() const {
    const double tick = 2 * std::numbers::pi / sim::kXTicksPerRev;
    for (std::size_t j = 0; j < physics->joints(); ++j) {
      const auto& goals = physics->goals(j);
      ASSERT_GT(goals.size(), 100u) << physics->name(j) << " received few goals";
      const double vmax = physics->limit(j);
      int reported = 0;
      double moved = 0.0;
      for (std::size_t k = 1; k < goals.size(); ++k) {
        if (!goals[k].torque || !goals[k - 1].torque) continue;
        const double step = std::abs(goals[k].rad - goals[k - 1].rad);
        moved = std::max(moved, step);
        const double elapsed = to_seconds(goals[k].at - goals[k - 1].at);
        const double bound = vmax * period_s + 2 * tick;
        if (step > bound && reported++ < 3) {
          ADD_FAILURE() << physics->name(j) << ": goal " << k << " moved "
                        << step * 180 / std::numbers::pi << " deg " << elapsed * 1e3
                        << " ms after the one before; at most " << bound * 180 / std::numbers::pi
                        << " deg allowed (" << vmax * 180 / std::numbers::pi << " deg/s)";
        }
      }
      EXPECT_GT(moved, 0.5 * vmax * period_s) << physics->name(j) << " never moved at speed";
    }
  }

 private:
  std::atomic<bool> active_{false};
};

std::uint64_t late_cycles(const RunSummary& s) {
  return s.buses.empty() ? 0 : s.buses[0].late_cycles;
}

// Healthy wall-clock run: the baseline of the checks below.
TEST(LateBus, OnTimeBusGoalsAreContinuous) {
  Rig r;
  const RunSummary s = r.rig->run(1.5);
  EXPECT_EQ(s.end_reason, EndReason::duration) << (s.faults.empty() ? "" : s.faults[0]);
  EXPECT_TRUE(s.faults.empty());
  r.expect_continuous_goals();
}

// Every 25th read waits 12 ms (more than two 5 ms cycles) before the answers
// are read: the bus is late for two or three cycles each time.
TEST(LateBus, LateAnswersKeepTheGoalsContinuous) {
  Rig r;
  r.make_late(BusCall::read, 50, 25, std::chrono::milliseconds(12));
  const RunSummary s = r.rig->run(1.5);
  EXPECT_GT(r.held.load(), 5);
  EXPECT_GT(late_cycles(s), static_cast<std::uint64_t>(r.held.load()));
  EXPECT_EQ(s.end_reason, EndReason::duration) << (s.faults.empty() ? "" : s.faults[0]);
  EXPECT_TRUE(s.faults.empty());
  r.expect_continuous_goals();
}

// Every 25th Sync Write goes out 22 ms late: its goal is stale when it
// arrives, and the next goal must not be four cycles of full-speed motion
// beyond it.
TEST(LateBus, ALateWriteIsNotFollowedByAJump) {
  Rig r;
  r.make_late(BusCall::write, 50, 25, std::chrono::milliseconds(22));
  const RunSummary s = r.rig->run(1.5);
  EXPECT_GT(r.held.load(), 5);
  EXPECT_GT(late_cycles(s), static_cast<std::uint64_t>(r.held.load()));
  EXPECT_EQ(s.end_reason, EndReason::duration) << (s.faults.empty() ? "" : s.faults[0]);
  r.expect_continuous_goals();
}

// One read held 1.2 s: over twice the watchdog, within the grace for a
// busy bus. The run goes on and ends by its duration.
TEST(LateBus, ABusLateWithinTheGraceDoesNotFault) {
  Rig r;
  r.make_late(BusCall::read, 100, 1'000'000, std::chrono::milliseconds(1200));
  const RunSummary s = r.rig->run(2.5);
  EXPECT_EQ(r.held.load(), 1);
  EXPECT_GT(late_cycles(s), 120u);  // 1.2 s at 200 Hz is 240 cycles
  EXPECT_EQ(s.end_reason, EndReason::duration) << (s.faults.empty() ? "" : s.faults[0]);
  EXPECT_TRUE(s.faults.empty());
  for (const auto& d : s.devices) EXPECT_FALSE(d.status.faulted) << d.joint;
  r.expect_continuous_goals();
}

// One read held 3.5 s, longer than the grace (2.5 s for a 0.5 s
// watchdog): every servo on the bus is faulted, and not before the grace
// had passed since the last read that came back.
TEST(LateBus, ABusStuckBeyondTheGraceFaultsAfterIt) {
  Rig r;
  const MonotonicClock wall;
  std::atomic<Nanos> last_read_done{0};
  std::atomic<Nanos> stuck_at{0};
  std::atomic<bool> active{false};
  r.rig->on_bus_call = [&](std::size_t, BusCall c, std::uint64_t index) {
    if (c == BusCall::activate) active = true;
    if (c != BusCall::read || !active) return;
    // The hook runs before each read, so after the read before it came back.
    if (index == 150) {
      stuck_at = wall.now();
      std::this_thread::sleep_for(std::chrono::milliseconds(3500));
      ++r.held;
    } else if (index < 150) {
      last_read_done = wall.now();
    }
  };
  std::atomic<Nanos> fault_seen{0};
  RunOptions options = r.rig->options(8.0);
  options.on_motion_end = [&] { fault_seen = wall.now(); };
  const RunSummary s = r.rig->run(options);
  EXPECT_EQ(r.held.load(), 1);
  EXPECT_EQ(s.end_reason, EndReason::fault);
  EXPECT_EQ(s.faults.size(), 12u);
  for (const auto& line : s.faults)
    EXPECT_NE(line.find("no valid answer"), std::string::npos) << line;
  for (const auto& d : s.devices) EXPECT_TRUE(d.status.faulted) << d.joint;
  ASSERT_GT(stuck_at.load(), 0);
  ASSERT_GT(fault_seen.load(), stuck_at.load());
  // The loop's last good answer came no earlier than the hook before the
  // read that delivered it: the fault came more than the grace after that.
  const double watchdog = r.rig->config().safety.watchdog_timeout_s;
  ASSERT_EQ(watchdog, kWatchdogS);
  const double grace = std::min(10 * watchdog, watchdog + 2.0);
  EXPECT_GT(to_seconds(fault_seen.load() - last_read_done.load()), grace);
  EXPECT_GT(late_cycles(s), 0u);
}

}  // namespace
}  // namespace animrt
