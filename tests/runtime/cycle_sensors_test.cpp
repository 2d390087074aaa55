// Sensors in the cycle: the trunk's IMU reaches the motion source, a stale
// IMU is late and then faulted as a silent servo is, and the tilt watch
// stops a figure that is pushed over by a hold or by torque off.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "animrt/runtime/cycle.hpp"
#include "support/alloc_counter.hpp"

namespace animrt::sensors_test {
namespace {

constexpr double kRate = 100.0;
constexpr double kDeg = std::numbers::pi / 180.0;

class SensingSource : public MotionSource {
 public:
  SensingSource() : driven_{0, 1} {}
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override {
    targets[0] = 0.2 * std::sin(3.0 * t);
    targets[1] = 0.2 * std::cos(3.0 * t) - 0.2;
  }
  void sense(const Sensors& sensors) override {
    ++sensed;
    roll = sensors.imu ? roll_of(sensors.imu->quat) : std::nan("");
  }
  int sensed = 0;
  double roll = 0.0;

 private:
  std::vector<int> driven_;
};

RobotModel model_with_imu() {
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
  for (int j = 0; j < 2; ++j) {
    m.joint_names.push_back("j" + std::to_string(j));
    m.limits.push_back(JointLimits{-1.5, 1.5, 2.0, 20.0});
    m.home.push_back(0.5);
    m.prismatic.push_back(0);
    m.following_error.push_back(m.safety.following_error_rad);
    m.slots.push_back(JointSlot{0, static_cast<std::size_t>(j)});
  }
  m.buses.push_back(BusModel{"a", {0, 1}, {1, 2}});
  m.imus.push_back(ImuModel{"trunk", 0.05});
  return m;
}

// Ideal servos; an IMU that reports `roll(t)` every cycle unless `silent(t)`.
struct Rig {
  explicit Rig(RobotModel m) : model(std::move(m)), state(model) {
    positions.assign(2, 0.0);
    health.assign(2, DeviceHealth::ok);
    std::vector<double> first(model.home);
    motion.sample(0.0, first);
    state.begin(model, positions, first);
  }
  const CycleOutputs& cycle() {
    const double t = count / kRate;
    if (!silent(t)) {
      imu.valid = true;
      imu.reading.quat = quat_from_ypr(0.3, 0.0, roll(t));
      imu.reading.time_s = t;
    }
    bus = BusIo{true, positions, health};
    in.t = t;
    in.buses = std::span<const BusIo>(&bus, 1);
    in.imus = std::span<const ImuIo>(&imu, 1);
    const CycleOutputs& out = step(model, motion, state, in);
    if (out.write[0]) positions = out.bus_commands[0];
    for (const CycleEvent& e : out.events) events.push_back(e);
    torque_off = torque_off || out.torque_off_now;
    ++count;
    return out;
  }
  void run(double until_s) {
    while (count / kRate < until_s && !state.done()) cycle();
  }
  const CycleEvent* first(EventKind kind) const {
    for (const auto& e : events)
      if (e.kind == kind) return &e;
    return nullptr;
  }

  RobotModel model;
  SensingSource motion;
  CycleState state;
  std::vector<double> positions;
  std::vector<DeviceHealth> health;
  BusIo bus;
  ImuIo imu;
  CycleInputs in;
  std::function<double(double)> roll = [](double) { return 0.0; };
  std::function<bool(double)> silent = [](double) { return false; };
  int count = 0;
  bool torque_off = false;
  std::vector<CycleEvent> events;
};

// Pushed over at 1 s: the roll grows to 90 degrees in half a second.
double push_over(double t) { return t < 1.0 ? 0.0 : std::min(90.0, (t - 1.0) * 180.0) * kDeg; }

TEST(CycleSensors, TheMotionReadsTheTrunksAttitude) {
  Rig rig(model_with_imu());
  rig.roll = [](double t) { return 0.1 * t; };
  rig.run(1.0);
  EXPECT_GT(rig.motion.sensed, 50);
  EXPECT_NEAR(rig.motion.roll, 0.1 * (rig.count - 1) / kRate, 1e-9);
}

TEST(CycleSensors, APushedOverFigureHoldsWhereItIsThenEnds) {
  Rig rig(model_with_imu());
  rig.roll = push_over;
  while (!rig.first(EventKind::tilted) && rig.count < 1000) rig.cycle();
  const std::vector<double> before = rig.positions;
  rig.run(10.0);
  ASSERT_TRUE(rig.state.done());
  const CycleEvent* tilted = rig.first(EventKind::tilted);
  ASSERT_NE(tilted, nullptr);
  // 45 degrees at 1.25 s, held 0.1 s beyond the limit.
  EXPECT_NEAR(tilted->t, 1.35, 0.011);
  EXPECT_GT(tilted->value, 45 * kDeg);
  EXPECT_TRUE(rig.state.end().tilted);
  EXPECT_TRUE(rig.state.end().fault);
  EXPECT_FALSE(rig.torque_off);
  // Held, not ramped home (0.5): the joints stay within the braking
  // distance of where the motion had them.
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_LT(std::abs(rig.positions[j] - before[j]), 0.02) << j;
    EXPECT_GT(std::abs(rig.positions[j] - 0.5), 0.1) << j;
  }
}

TEST(CycleSensors, APushedOverFigureCanLetGoAtOnce) {
  RobotModel m = model_with_imu();
  m.safety.on_tilt = SafetyConfig::OnTilt::torque_off;
  Rig rig(std::move(m));
  rig.roll = push_over;
  rig.run(10.0);
  ASSERT_TRUE(rig.state.done());
  ASSERT_NE(rig.first(EventKind::tilted), nullptr);
  EXPECT_TRUE(rig.torque_off);
  EXPECT_TRUE(rig.state.end().torque_cut);
  EXPECT_NEAR(rig.state.motion_time(), 1.35 - 0.2, 0.011);
}

TEST(CycleSensors, ABriefTiltOrAWatchLeftOffDoesNotStop) {
  Rig rig(model_with_imu());
  rig.roll = [](double t) { return t > 1.0 && t < 1.05 ? 60 * kDeg : 0.0; };  // a knock
  rig.in.motion_duration_s = 2.0;
  rig.run(10.0);
  EXPECT_EQ(rig.first(EventKind::tilted), nullptr);
  EXPECT_FALSE(rig.state.end().fault);

  RobotModel m = model_with_imu();
  m.safety.tilt_limit_rad = 0.0;
  Rig off(std::move(m));
  off.roll = push_over;
  off.in.motion_duration_s = 2.0;
  off.run(10.0);
  EXPECT_EQ(off.first(EventKind::tilted), nullptr);
  EXPECT_NEAR(off.state.max_tilt(), 90 * kDeg, 1e-6);
}

TEST(CycleSensors, AStaleImuIsLateThenFaultedAndRampsHome) {
  Rig rig(model_with_imu());
  // Silent for 45 ms (late, the last reading kept), then for good at 1.5 s.
  rig.silent = [](double t) { return (t > 1.0 && t < 1.045) || t > 1.5; };
  rig.run(1.5);
  // Late once a reading is older than a report and a loop period (20 ms):
  // 30 and 40 ms into the glitch; no fault.
  EXPECT_EQ(rig.state.imu_late_cycles()[0], 2u);
  EXPECT_EQ(rig.first(EventKind::sensor_stale), nullptr);
  // The reports of 1.01 to 1.04 s never came.
  EXPECT_EQ(rig.state.imu_missing(0, 100.0), 4u);
  const std::uint64_t readings = rig.state.imu_readings(0);
  EXPECT_EQ(readings, static_cast<std::uint64_t>(rig.count) - 4u);
  rig.run(10.0);
  // Every report after 1.5 s is missing, up to the last cycle's own.
  const double last = (rig.count - 1) / kRate;
  EXPECT_EQ(rig.state.imu_missing(0, 100.0),
            4u + static_cast<std::uint64_t>(std::llround((last - 1.5) * 100.0)) - 1u);
  EXPECT_EQ(rig.state.imu_readings(0), readings + 1u);  // the one at 1.5 s
  ASSERT_TRUE(rig.state.done());
  const CycleEvent* stale = rig.first(EventKind::sensor_stale);
  ASSERT_NE(stale, nullptr);
  EXPECT_EQ(stale->bus, 0u);
  EXPECT_GT(stale->t, 1.5 + 0.05);
  EXPECT_LT(stale->t, 1.5 + 0.05 + 0.021);
  EXPECT_TRUE(rig.state.end().fault);
  EXPECT_FALSE(rig.state.end().tilted);
  EXPECT_EQ(rig.state.imu_faulted()[0], 1);
  EXPECT_GE(rig.state.imu_late_cycles()[0], 2u + 3u);
  // Ramped home, and the motion saw no reading once it was stale.
  for (double p : rig.positions) EXPECT_NEAR(p, 0.5, 1e-3);
}

TEST(CycleSensors, AnImuThatNeverReportsIsFaulted) {
  Rig rig(model_with_imu());
  rig.silent = [](double) { return true; };
  rig.run(1.0);
  ASSERT_NE(rig.first(EventKind::sensor_stale), nullptr);
  EXPECT_NEAR(rig.first(EventKind::sensor_stale)->t, 0.06, 0.011);
}

TEST(CycleSensors, StepWithImuReadsDoesNotAllocate) {
  Rig rig(model_with_imu());
  rig.roll = push_over;
  rig.cycle();  // std::function's first call is the test's, not the cycle's
  test::AllocationCounter counter;
  for (int i = 0; i < 400 && !rig.state.done(); ++i) {
    const double t = rig.count / kRate;
    rig.imu.valid = true;
    rig.imu.reading.quat = quat_from_ypr(0.0, 0.0, push_over(t));
    rig.imu.reading.time_s = i % 9 == 0 ? t - 0.02 : t;
    rig.in.t = t;
    step(rig.model, rig.motion, rig.state, rig.in);
    ++rig.count;
  }
  EXPECT_EQ(counter.count(), 0);
  EXPECT_TRUE(rig.state.end().tilted);  // the tilt path ran
}

}  // namespace
}  // namespace animrt::sensors_test
