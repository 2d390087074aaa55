// Crossfades between every pair of shipped motions that fit a shipped robot,
// on a simulated clock: the blend may ask a joint for no more velocity or
// acceleration than the two motions ask themselves, plus the joint's limit
// (a jump would ask for orders of magnitude more). The cue asks for no
// crossfade time at all, so only the ease-in keeps a far start smooth.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <thread>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/cues/pose_source.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

namespace fs = std::filesystem;
const std::string kFadeRoot = ANIMRT_SOURCE_DIR;

// A motion borrowed by a player, so that one set of motions serves every pair.
class Borrowed final : public MotionSource {
 public:
  explicit Borrowed(const MotionSource& source) : source_(source) {}
  std::span<const int> driven_joints() const override { return source_.driven_joints(); }
  void sample(double t, std::span<double> targets) const override { source_.sample(t, targets); }

 private:
  const MotionSource& source_;
};

struct Motion {
  std::string name;
  std::unique_ptr<MotionSource> source;
};

// Every shipped show and gait that loads for the robot, and a pose far from
// its home (each joint near its upper limit).
std::vector<Motion> fitting_motions(const RobotConfig& robot) {
  std::vector<Motion> motions;
  for (const char* kind : {"shows", "gaits"}) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(kFadeRoot + "/configs/" + kind)) {
      const std::string name = entry.path().filename().string();
      if (name.find(".calibration.") == std::string::npos) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      MotionConfig motion;
      motion.type = std::string(kind) == "shows" ? "show" : "gait";
      motion.file = file.string();
      try {
        motions.push_back({file.filename().string(), load_motion_source(motion, robot)});
      } catch (const InputError&) {
        // made for another robot
      }
    }
  }
  std::vector<std::pair<int, double>> far;
  for (std::size_t j = 0; j < robot.joints.size(); ++j) {
    const JointLimits& l = robot.joints[j].limits;
    far.emplace_back(static_cast<int>(j), l.min_position + 0.9 * (l.max_position - l.min_position));
  }
  motions.push_back({"far pose", make_pose_source(std::move(far))});
  return motions;
}

struct Trace {
  std::vector<std::vector<double>> x;  // per cycle, every joint
};

Trace play(const MotionSource& source, std::size_t joints, double t_from, int cycles, double dt,
           const std::vector<double>& home) {
  Trace trace;
  for (int k = 0; k < cycles; ++k) {
    std::vector<double> pose = home;
    source.sample(std::max(0.0, t_from + k * dt), pose);
    trace.x.push_back(pose);
    (void)joints;
  }
  return trace;
}

// Largest first and second differences of joint j over cycles [from, to).
std::pair<double, double> peaks(const Trace& trace, std::size_t j, int from, int to) {
  double d1 = 0.0, d2 = 0.0;
  for (int k = std::max(from, 1); k + 1 < to; ++k) {
    const auto& x = trace.x;
    d1 = std::max(d1, std::abs(x[k][j] - x[k - 1][j]));
    d2 = std::max(d2, std::abs(x[k + 1][j] - 2 * x[k][j] + x[k - 1][j]));
  }
  return {d1, d2};
}

void check_pair(const RobotConfig& robot, const Motion& a, const Motion& b) {
  std::vector<Cue> cues(2);
  cues[0].name = "a";
  cues[0].steps.push_back({std::make_unique<Borrowed>(*a.source), kForever});
  cues[1].name = "b";
  cues[1].steps.push_back({std::make_unique<Borrowed>(*b.source), kForever});
  cues[0].crossfade_s = cues[1].crossfade_s = 0.0;
  CueRequests requests;
  CuePlayer player(std::move(cues), 0, robot.joints, requests);
  const double dt = 1.0 / robot.rate_hz;
  const int ks = static_cast<int>(std::lround(1.37 / dt));  // the trigger's cycle
  std::vector<double> home;
  for (const JointSpec& joint : robot.joints) home.push_back(joint.home);
  Trace out;
  int cycles = ks + 1;
  for (int k = 0; k < cycles; ++k) {
    if (k == ks) {
      requests.cue(1);
      std::vector<double> pose = home;
      player.sample(k * dt, pose);
      out.x.push_back(pose);
      cycles = ks + static_cast<int>(std::ceil(player.last_crossfade_s() / dt)) + 50;
      continue;
    }
    std::vector<double> pose = home;
    player.sample(k * dt, pose);
    out.x.push_back(pose);
  }
  const Trace ta = play(*a.source, home.size(), 0.0, cycles, dt, home);
  const Trace tb = play(*b.source, home.size(), -ks * dt, cycles, dt, home);
  for (int j : player.driven_joints()) {
    const auto jj = static_cast<std::size_t>(j);
    const JointLimits& l = robot.joints[jj].limits;
    const auto [va, aa] = peaks(ta, jj, ks - 1, cycles);
    const auto [vb, ab] = peaks(tb, jj, ks + 1, cycles);
    const auto [v, acc] = peaks(out, jj, ks - 1, cycles);
    const std::string what =
        robot.name + ": " + a.name + " -> " + b.name + ", joint " + robot.joints[jj].name;
    EXPECT_LE(v, std::max(va, vb) + l.max_velocity * dt) << what;
    EXPECT_LE(acc, std::max(aa, ab) + l.max_acceleration * dt * dt) << what;
  }
}

TEST(Crossfade, NoJumpBetweenAnyTwoShippedMotionsOfARobot) {
  int pairs = 0;
  for (const char* name : {"animatronic", "quadruped", "pony", "horse", "arm_sts"}) {
    const RobotConfig robot = load_robot_config(kFadeRoot + "/configs/robots/" + name + ".yaml");
    const std::vector<Motion> motions = fitting_motions(robot);
    ASSERT_GE(motions.size(), 2u) << name;
    for (const Motion& a : motions) {
      for (const Motion& b : motions) {
        if (&a == &b) continue;
        check_pair(robot, a, b);
        ++pairs;
      }
    }
  }
  EXPECT_GE(pairs, 10);
  std::cout << pairs << " pairs\n";
}

// Two poses and a player over them, idle on the first.
struct TwoPoses {
  RobotConfig robot = load_robot_config(kFadeRoot + "/configs/robots/animatronic.yaml");
  CueRequests requests;
  std::unique_ptr<CuePlayer> player;
  explicit TwoPoses(double crossfade_s, double pan_deg = 2.0) {
    std::vector<Cue> cues(2);
    cues[0].name = "rest";
    cues[0].steps.push_back({make_pose_source({{0, 0.0}}), kForever});
    cues[1].name = "turn";
    cues[1].steps.push_back({make_pose_source({{0, deg_to_rad(pan_deg)}}), kForever});
    cues[1].crossfade_s = crossfade_s;
    player = std::make_unique<CuePlayer>(std::move(cues), 0, robot.joints, requests);
  }
  std::vector<double> pose = std::vector<double>(robot.joints.size(), 0.0);
  double at(double t) {
    player->sample(t, pose);
    return pose[0];
  }
};

// A motion that keeps the steering and sensor readings it was last given.
class Listens final : public MotionSource {
 public:
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double, std::span<double> targets) const override { targets[0] = 0.0; }
  void steer(const MotionCommand& command) override { steered = command; }
  void sense(const Sensors& sensors) override { sensed = &sensors; }
  MotionCommand steered{-1.0, -1.0};
  const Sensors* sensed = nullptr;

 private:
  std::vector<int> driven_{0};
};

// The herd's or the dashboard's steering and the trunk's IMU reach a cue's
// walk, the one playing and the one that will (a steered or balanced gait).
TEST(Crossfade, EveryCuesMotionIsSteeredAndSensesAsItWouldAlone) {
  const RobotConfig robot = load_robot_config(kFadeRoot + "/configs/robots/animatronic.yaml");
  CueRequests requests;
  std::vector<Cue> cues(2);
  auto a = std::make_unique<Listens>();
  auto b = std::make_unique<Listens>();
  const Listens* pa = a.get();
  const Listens* pb = b.get();
  cues[0].name = "rest";
  cues[0].steps.push_back({std::move(a), kForever});
  cues[1].name = "walk";
  cues[1].steps.push_back({std::move(b), kForever});
  CuePlayer player(std::move(cues), 0, robot.joints, requests);
  std::vector<double> pose(robot.joints.size(), 0.0);
  player.sample(0.0, pose);
  player.steer(MotionCommand{0.4, 0.1});
  const Sensors sensors{};
  player.sense(sensors);
  for (const Listens* l : {pa, pb}) {
    EXPECT_DOUBLE_EQ(l->steered.speed_m_s, 0.4);
    EXPECT_DOUBLE_EQ(l->steered.turn_rad_s, 0.1);
    EXPECT_EQ(l->sensed, &sensors);
  }
}

TEST(Crossfade, TakesTheCuesTimeWhenTheLimitsAllowIt) {
  TwoPoses f(2.0);
  f.at(0.0);
  f.requests.cue(1);
  f.at(1.0);
  EXPECT_DOUBLE_EQ(f.player->last_crossfade_s(), 2.0);
  EXPECT_NEAR(f.at(2.0), deg_to_rad(1.0), 1e-9);  // halfway, half the way
  EXPECT_NEAR(f.at(3.0), deg_to_rad(2.0), 1e-12);
  EXPECT_EQ(f.player->starts(1), 1u);
  EXPECT_EQ(f.player->current_cue(), 1);
  f.requests.cue(1);  // asked for again: it starts again
  f.at(3.01);
  EXPECT_EQ(f.player->starts(1), 2u);
  EXPECT_EQ(f.player->starts(0), 1u);
}

TEST(Crossfade, AFarCueEasesInOverLongerThanAsked) {
  TwoPoses f(0.1, 50.0);  // 50 degrees of neck pan in 0.1 s would be a jump
  f.at(0.0);
  f.requests.cue(1);
  f.at(0.01);
  const JointLimits& l = f.robot.joints[0].limits;
  const double gap = deg_to_rad(50.0);
  EXPECT_GE(
      f.player->last_crossfade_s(),
      std::sqrt(10.0 / std::sqrt(3.0) * gap / (kCrossfadeLimitShare * l.max_acceleration)) - 1e-9);
}

TEST(Crossfade, APauseSlowsToAHaltAndResumesWithoutAStep) {
  const RobotConfig robot = load_robot_config(kFadeRoot + "/configs/robots/animatronic.yaml");
  MotionConfig gait{"gait", kFadeRoot + "/configs/shows/neck_idle_gait.yaml", {}, "", nullptr, {}};
  std::vector<Cue> cues(1);
  cues[0].name = "sway";
  cues[0].steps.push_back({load_motion_source(gait, robot), kForever});
  CueRequests requests;
  CuePlayer player(std::move(cues), 0, robot.joints, requests);
  const double dt = 0.01;
  std::vector<double> x;
  for (int k = 0; k < 400; ++k) {
    if (k == 100) requests.pause(true);
    if (k == 250) requests.pause(false);
    std::vector<double> pose(robot.joints.size(), 0.0);
    player.sample(k * dt, pose);
    x.push_back(pose[0]);
  }
  // Held still once the pause's ramp is over.
  EXPECT_NEAR(x[249], x[100 + static_cast<int>(kPauseRampS / dt) + 1], 1e-12);
  EXPECT_GT(std::abs(x[399] - x[249]), 1e-3);  // and moving again
  const double a = robot.joints[0].limits.max_acceleration * dt * dt;
  for (std::size_t k = 1; k + 1 < x.size(); ++k) {
    EXPECT_LE(std::abs(x[k + 1] - 2 * x[k] + x[k - 1]), a) << "cycle " << k;
  }
}

// 10,000 triggers from two threads while the cycle plays: it never
// allocates, never jumps, and ends on the newest cue asked for.
TEST(CueRequests, ABurstOfTriggersNeitherAllocatesNorJumpsAndTheNewestWins) {
  TwoPoses f(0.2, 30.0);
  std::atomic<bool> go{false};
  auto writer = [&f, &go](int first) {
    while (!go.load()) {
    }
    for (int i = 0; i < 5000; ++i) f.requests.cue((first + i) % 2);
  };
  std::thread w0(writer, 0), w1(writer, 1);
  std::vector<double> x;
  x.reserve(1 << 22);
  f.at(0.0);
  long allocations = 0;
  int k = 1;
  {
    test::AllocationCounter counter;
    go.store(true);
    // The cycle plays on until both writers are through.
    for (; k < 2000 || (f.requests.posted() < 10000 && k < (1 << 21)); ++k) {
      x.push_back(f.at(k * 0.01));
    }
    allocations = counter.count();
  }
  w0.join();
  w1.join();
  f.requests.cue(1);
  for (const int end = k + 600; k < end; ++k) x.push_back(f.at(k * 0.01));
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(f.requests.posted(), 10001u);
  EXPECT_EQ(f.player->current_cue(), 1);
  EXPECT_NEAR(x.back(), deg_to_rad(30.0), 1e-9);
  const JointLimits& l = f.robot.joints[0].limits;
  for (std::size_t c = 1; c + 1 < x.size(); ++c) {
    ASSERT_LE(std::abs(x[c] - x[c - 1]), l.max_velocity * 0.01) << "cycle " << c;
    ASSERT_LE(std::abs(x[c + 1] - 2 * x[c] + x[c - 1]), l.max_acceleration * 1e-4) << c;
  }
}

// Once the motion has ended, later requests are neither taken nor counted;
// one posted before is still there to take.
TEST(CueRequests, RequestsAfterCloseAreNeitherTakenNorCounted) {
  CueRequests requests;
  requests.cue(2);
  requests.pause(true);
  requests.close();
  requests.cue(1);
  requests.pause(false);
  int index = -1;
  ASSERT_TRUE(requests.take(index));
  EXPECT_EQ(index, 2);
  EXPECT_FALSE(requests.take(index));
  EXPECT_EQ(requests.posted(), 1u);
  EXPECT_TRUE(requests.paused());
}

}  // namespace
}  // namespace animrt
