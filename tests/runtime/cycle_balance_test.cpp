// A balanced gait in the cycle: the IMU's attitude moves its reflex, a
// silent IMU is counted late while the reflex holds (no jump), and the tilt
// watch still stops a figure that goes over.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "animrt/controllers/gait/balanced_gait_source.hpp"
#include "animrt/runtime/cycle.hpp"

namespace animrt::balance_cycle_test {
namespace {

constexpr double kRate = 100.0;
constexpr double kDeg = std::numbers::pi / 180.0;

// Joint 0 at 0.3 rad, always: what moves it is the reflex alone.
class StillCurve final : public MotionSource {
 public:
  std::span<const int> driven_joints() const override { return joints_; }
  void sample(double /*t*/, std::span<double> targets) const override { targets[0] = 0.3; }

 private:
  std::array<int, 1> joints_{0};
};

// One front-left leg on joint 0, always down, 0.5 m down the trunk per rad.
class OneLeg final : public LegModel {
 public:
  std::size_t leg_count() const override { return 1; }
  BalanceLeg where(std::size_t /*leg*/) const override { return {1.0, 1.0}; }
  std::span<const int> joints(std::size_t /*leg*/) const override { return joint_; }
  void pose(std::span<const double> /*positions*/, const std::array<double, 4>& /*q*/) override {}
  bool on_ground(std::size_t /*leg*/) const override { return true; }
  void down_per_rad(std::size_t /*leg*/, std::span<double> out) override { out[0] = 0.5; }
  std::size_t max_leg_joints() const override { return 1; }

 private:
  std::array<int, 1> joint_{0};
};

RobotModel one_joint_with_imu() {
  RobotModel m;
  m.name = "test";
  m.rate_hz = kRate;
  m.period = from_seconds(1.0 / kRate);
  m.dt = 1.0 / kRate;
  m.safety.start_ramp_s = 0.2;
  m.safety.stop_ramp_s = 0.5;
  m.safety.tilt_limit_rad = 45 * kDeg;
  m.safety.tilt_time_s = 0.1;
  m.safety.tilt_hold_s = 0.3;
  m.motion = "gait test.yaml";
  m.joint_names.push_back("j0");
  m.limits.push_back(JointLimits{-1.5, 1.5, 10.0, 1000.0});
  m.home.push_back(0.3);
  m.prismatic.push_back(0);
  m.following_error.push_back(m.safety.following_error_rad);
  m.slots.push_back(JointSlot{0, 0});
  m.buses.push_back(BusModel{"a", {0}, {1}});
  m.imus.push_back(ImuModel{"trunk", 0.05});
  return m;
}

GaitBalance gains() {
  GaitBalance b;
  b.tilt_m = 0.3;
  return b;
}

// Ideal servo; the IMU reports pitch(t) each cycle unless silent(t).
struct Rig {
  Rig()
      : model(one_joint_with_imu()),
        motion(std::make_unique<StillCurve>(), gains(), 1),
        state(model) {
    motion.attach(std::make_unique<OneLeg>());
    std::vector<double> first{0.3};
    state.begin(model, positions, first);
  }
  void cycle() {
    const double t = count / kRate;
    if (!silent(t)) {
      imu.valid = true;
      imu.reading.quat = quat_from_ypr(0.0, pitch(t), 0.0);
      imu.reading.time_s = t;
    }
    bus = BusIo{true, positions, health};
    in.t = t;
    in.buses = std::span<const BusIo>(&bus, 1);
    in.imus = std::span<const ImuIo>(&imu, 1);
    const CycleOutputs& out = step(model, motion, state, in);
    if (out.write[0]) positions = out.bus_commands[0];
    for (const CycleEvent& e : out.events) tilted = tilted || e.kind == EventKind::tilted;
    ++count;
  }
  void run_until(double t) {
    while (count / kRate < t - 1e-9 && !state.done()) cycle();
  }

  RobotModel model;
  BalancedGaitSource motion;
  CycleState state;
  std::vector<double> positions{0.3};
  std::vector<DeviceHealth> health{DeviceHealth::ok};
  BusIo bus;
  ImuIo imu;
  CycleInputs in;
  std::function<double(double)> pitch = [](double) { return 0.0; };
  std::function<bool(double)> silent = [](double) { return false; };
  int count = 0;
  bool tilted = false;
};

// The joint's command is the curve (0.3) plus the front leg's stretch
// through its Jacobian: 0.3 + 0.6 sin(pitch) for a trunk pitched nose down.
double balanced(double pitch) { return 0.3 + 2.0 * 0.3 * std::sin(pitch); }

TEST(CycleBalance, TheReflexFollowsTheImuAndHoldsWhileItIsSilent) {
  Rig rig;
  // Nose down ever more from 0.5 s; the IMU silent after 1.0 s for 45 ms.
  rig.pitch = [](double t) { return t < 0.5 ? 0.0 : 0.1 * (t - 0.5); };
  rig.silent = [](double t) { return t > 1.0 + 1e-9 && t < 1.045; };
  rig.run_until(1.01);  // the cycle at 1.0 s ran: its reading was the last
  const double held = rig.positions[0];
  EXPECT_NEAR(held, balanced(0.05), 2e-3);
  while (rig.count / kRate < 1.045 - 1e-9) {
    rig.cycle();
    EXPECT_NEAR(rig.positions[0], held, 1e-3) << "t = " << (rig.count - 1) / kRate;
  }
  EXPECT_EQ(rig.state.imu_late_cycles()[0], 2u);  // older than a report and a period
  EXPECT_FALSE(rig.state.end().fault);
  rig.run_until(1.5);
  EXPECT_NEAR(rig.positions[0], balanced(0.1 * (1.49 - 0.5)), 2e-3);
  EXPECT_GT(rig.motion.readings(), 100u);
}

TEST(CycleBalance, TheTiltWatchStillStopsAFigureGoingOver) {
  Rig rig;
  rig.pitch = [](double t) { return t < 1.0 ? 0.0 : std::min(90.0, (t - 1.0) * 180.0) * kDeg; };
  rig.run_until(10.0);
  EXPECT_TRUE(rig.tilted);
  EXPECT_TRUE(rig.state.end().tilted);
  EXPECT_TRUE(rig.state.done());
}

}  // namespace
}  // namespace animrt::balance_cycle_test
