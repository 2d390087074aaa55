// A cue whose transition is learned: the in-between from the present pose to
// the cue's pose is the sequence model's completion, computed off the cycle,
// eased in and out of the crossfade so nothing jumps at the seams; a model
// too slow falls back to the crossfade; a stop still winds down; a bad
// transition is refused at load with the cue file's line.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/cues/pose_source.hpp"
#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "seqnet/tiny_joint_model.hpp"
#include "support/alloc_counter.hpp"

namespace animrt::learned_transition_test {
namespace {

namespace fs = std::filesystem;
// Cycles and model frames on a binary grid, so that times compare exactly.
constexpr double kDt = 1.0 / 128;
constexpr double kFrameS = 1.0 / 16;  // 8 cycles

std::vector<JointSpec> joints(double max_velocity = 10.0) {
  std::vector<JointSpec> j(2);
  j[0].name = "hip";
  j[1].name = "knee";
  for (JointSpec& s : j) s.limits = {-3.0, 3.0, max_velocity, 100.0};
  return j;
}

// hip and knee swaying (0.5 Hz) about a centre, so a seam's jump would show.
class Sway final : public MotionSource {
 public:
  Sway(double hip, double knee) : hip_(hip), knee_(knee) {}
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override {
    targets[0] = hip_ + 0.3 * std::sin(kPi * t);
    targets[1] = knee_ + 0.2 * std::cos(kPi * t);
  }

 private:
  double hip_, knee_;
  std::vector<int> driven_ = {0, 1};
};

const seqnet::ModelFile& model() {
  static const seqnet::ModelFile m = seqnet::test::tiny_joint_model(0.1F);
  return m;
}

CueTransition learned() {
  CueTransition t;
  t.model = std::make_shared<const seqnet::ModelFile>(model());
  t.model_file = "tiny.model";
  t.frame_s = kFrameS;
  t.joints = {0, 1};
  return t;
}

// Cue 0 (idle) and cue 1, each a pose or a sway; cue 1's transition learned or not.
std::vector<Cue> cues(bool moving, bool with_model) {
  std::vector<Cue> c(2);
  c[0].name = "rest";
  c[1].name = "reach";
  if (moving) {
    c[0].steps.push_back({std::make_unique<Sway>(0.1, -0.2)});
    c[1].steps.push_back({std::make_unique<Sway>(0.6, 0.3)});
  } else {
    c[0].steps.push_back({make_pose_source({{0, 0.1}, {1, -0.2}})});
    c[1].steps.push_back({make_pose_source({{0, 0.6}, {1, 0.3}})});
  }
  for (Cue& cue : c) cue.crossfade_s = 1.0;
  if (with_model) c[1].transition = learned();
  return c;
}

struct Rig {
  CueRequests requests;
  CuePlayer player;
  double dt;
  std::vector<double> out = std::vector<double>(2, 0.0);
  int k = 0;  // cycles sampled
  Rig(bool moving, bool with_model, bool lockstep, double cycle = kDt, double max_velocity = 10.0)
      : player(cues(moving, with_model), 0, joints(max_velocity), requests), dt(cycle) {
    player.start(MotionClock{nullptr, 0, lockstep});
  }
  double t() const { return k * dt; }
  std::vector<double> step() {
    player.sample(t(), out);
    ++k;
    return out;
  }
};

// The model's completion called directly between two poses.
seqnet::FrameMatrix completion(const std::vector<double>& from, const std::vector<double>& to,
                               int frames) {
  seqnet::SeqNetInference net(model(), "tiny.model");
  seqnet::FrameMatrix keys(2, 2);
  keys << from[0], to[0], from[1], to[1];
  return net.complete(keys, {frames - 1}, TransitionWorker::completion_options()).frames;
}

// A stop's grant longer than anything here winds down: the grant is not the point.
constexpr double kAmpleGrantS = 100.0;

TEST(LearnedTransition, TheInBetweenIsTheModelsCompletionFromThePresentPose) {
  Rig rig(false, true, true);
  Rig plain(false, false, true);  // the same cues, crossfading
  std::vector<double> before;
  for (int i = 0; i < 50; ++i) before = rig.step(), plain.step();
  const int trigger = rig.k;
  rig.requests.cue(1);
  plain.requests.cue(1);
  std::vector<std::vector<double>> played, crossfaded;
  for (int i = 0; i < 160; ++i) played.push_back(rig.step()), crossfaded.push_back(plain.step());
  ASSERT_EQ(rig.player.learned_played(), 1u);
  EXPECT_EQ(rig.player.learned_late(), 0u);
  EXPECT_EQ(rig.player.starts(1), 1u);
  ASSERT_DOUBLE_EQ(rig.player.last_crossfade_s(), 1.0);  // not lengthened: 16 frames
  const seqnet::FrameMatrix frames = completion(before, {0.6, 0.3}, 16);
  ASSERT_EQ(frames.cols(), 17);
  // Between the easings (a quarter of the transition at each end) the
  // targets are the model's frames, at the frames' times.
  double apart = 0.0;
  for (int f = 4; f <= 12; ++f) {
    const auto& at = played[static_cast<std::size_t>(8 * f)];
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(at[static_cast<std::size_t>(j)], frames(j, f), 1e-9) << "frame " << f;
      apart = std::max(
          apart,
          std::abs(at[static_cast<std::size_t>(j)] -
                   crossfaded[static_cast<std::size_t>(8 * f)][static_cast<std::size_t>(j)]));
    }
  }
  EXPECT_GT(apart, 0.01)
      << "the model's in-between is the crossfade itself: the test shows nothing";
  // Where the transition ends, the cue's pose, as the crossfade's.
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(played.back()[static_cast<std::size_t>(j)],
                crossfaded.back()[static_cast<std::size_t>(j)], 1e-12);
  }
  (void)trigger;
}

// The change of acceleration from cycle to cycle (a jerk times the cycle):
// a velocity step of v at a seam shows as a change of about 2 v / kDt.
std::vector<double> acceleration_change(const std::vector<std::vector<double>>& x, int j,
                                        double dt) {
  std::vector<double> da(x.size(), 0.0);
  for (std::size_t k = 3; k < x.size(); ++k) {
    const auto p = [&](std::size_t i) { return x[i][static_cast<std::size_t>(j)]; };
    const double a1 = (p(k) - 2 * p(k - 1) + p(k - 2)) / (dt * dt);
    const double a0 = (p(k - 1) - 2 * p(k - 2) + p(k - 3)) / (dt * dt);
    da[k] = std::abs(a1 - a0);
  }
  return da;
}

TEST(LearnedTransition, NoJumpAtEitherSeamBetweenMovingMotions) {
  constexpr double dt = 1.0 / 1024;  // fine cycles: a jump stands out, a steep ease does not
  Rig rig(true, true, true, dt);
  std::vector<std::vector<double>> x;
  for (int i = 0; i < 400; ++i) x.push_back(rig.step());
  const std::size_t start = x.size();
  rig.requests.cue(1);
  for (int i = 0; i < 1300; ++i) x.push_back(rig.step());
  ASSERT_EQ(rig.player.learned_played(), 1u);
  const auto end =
      start + static_cast<std::size_t>(std::lround(rig.player.last_crossfade_s() / dt));
  // The model's own frames leave the present pose at another velocity than
  // the sway's (else this test could not tell a jump).
  const double fade = rig.player.last_crossfade_s();
  const seqnet::FrameMatrix frames =
      completion(x[start - 1], {0.6 + 0.3 * std::sin(kPi * fade), 0.3 + 0.2 * std::cos(kPi * fade)},
                 static_cast<int>(std::lround(fade / kFrameS)));
  const double model_v = (frames(0, 1) - frames(0, 0)) / kFrameS;
  const double sway_v = 0.3 * kPi * std::cos(kPi * static_cast<double>(start - 1) * dt);
  ASSERT_GT(std::abs(model_v - sway_v), 0.3);
  for (int j = 0; j < 2; ++j) {
    const std::vector<double> da = acceleration_change(x, j, dt);
    for (std::size_t seam : {start, end}) {
      for (std::size_t k = seam - 2; k <= seam + 2; ++k) {
        // A velocity step of 0.3 rad/s changes the acceleration by 300 rad/s^2
        // from one cycle to the next; the sway's own change is 0.01.
        EXPECT_LT(da[k], 3.0) << "joint " << j << " cycle " << k << " (seam at " << seam << ")";
      }
    }
  }
}

TEST(LearnedTransition, AModelTooSlowFallsBackToTheCrossfadeWithinTheBound) {
  for (bool lockstep : {false, true}) {
    Rig rig(true, true, lockstep);
    Rig plain(true, false, lockstep);
    // Longer than the bound (in wall time on a lockstep clock).
    const double bound_s = lockstep ? kLockstepLearnedWaitS : kLearnedWaitS;
    rig.player.transition_worker()->set_delay(
        std::chrono::milliseconds(static_cast<int>(bound_s * 1000) + 1000));
    for (int i = 0; i < 30; ++i) rig.step(), plain.step();
    rig.requests.cue(1);
    // Real time: the figure plays on for the bound (10 cycles), then crossfades.
    const int wait = lockstep ? 0 : static_cast<int>(std::ceil(kLearnedWaitS / kDt));
    for (int i = 0; i < wait; ++i) {
      const std::vector<double> a = rig.step(), b = plain.step();
      EXPECT_EQ(a, b) << "the figure did not play on while it waited";
    }
    plain.requests.cue(1);
    for (int i = 0; i < 120; ++i) {
      const std::vector<double> a = rig.step(), b = plain.step();
      ASSERT_EQ(a, b) << "not the crossfade at cycle " << i << (lockstep ? " (lockstep)" : "");
    }
    EXPECT_EQ(rig.player.learned_late(), 1u);
    EXPECT_EQ(rig.player.learned_played(), 0u);
    EXPECT_EQ(rig.player.starts(1), 1u);
  }
}

TEST(LearnedTransition, AStopDuringTheTransitionLetsItPlayOutAndStartsNothing) {
  Rig rig(true, true, true);
  Rig going(true, true, true);  // the same, never stopped
  for (int i = 0; i < 50; ++i) rig.step(), going.step();
  rig.requests.cue(1);
  going.requests.cue(1);
  for (int i = 0; i < 40; ++i) rig.step(), going.step();
  ASSERT_EQ(rig.player.learned_played(), 1u);
  rig.player.wind_down(rig.t(), kAmpleGrantS);
  rig.requests.cue(0);  // nothing starts once the stop began
  for (int i = 0; i < 200; ++i) {
    const std::vector<double> a = rig.step(), b = going.step();
    for (std::size_t j = 0; j < 2; ++j) ASSERT_NEAR(a[j], b[j], 1e-12) << "cycle " << i;
  }
  EXPECT_EQ(rig.player.starts(0), 1u);
}

TEST(LearnedTransition, AStopWhileTheInBetweenIsComputedGivesItUp) {
  Rig rig(true, true, false);
  Rig plain(true, false, false);
  rig.player.transition_worker()->set_delay(std::chrono::milliseconds(100));
  for (int i = 0; i < 30; ++i) rig.step(), plain.step();
  rig.requests.cue(1);
  rig.step(), plain.step();
  rig.player.wind_down(rig.t(), kAmpleGrantS);
  plain.player.wind_down(plain.t(), kAmpleGrantS);
  for (int i = 0; i < 50; ++i) {
    const std::vector<double> a = rig.step(), b = plain.step();
    ASSERT_EQ(a, b) << "cycle " << i;
  }
  // Well past its computation: still nothing started.
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  for (int i = 0; i < 10; ++i) rig.step();
  EXPECT_EQ(rig.player.starts(1), 0u);
  EXPECT_EQ(rig.player.learned_played() + rig.player.learned_late(), 0u);
}

TEST(LearnedTransition, ABurstOfTriggersComputesOneInBetweenAtATime) {
  Rig rig(false, true, false);
  rig.player.transition_worker()->set_delay(std::chrono::milliseconds(20));
  for (int i = 0; i < 10; ++i) rig.step();
  const auto begin = std::chrono::steady_clock::now();
  for (int i = 0; i < 2000; ++i) {
    rig.requests.cue(1);
    rig.step();
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  // Each request replaces the one waiting; the worker took a new job only
  // when it had finished the last (one per 20 ms at most).
  EXPECT_LE(rig.player.transition_worker()->jobs(), 2 + static_cast<std::uint64_t>(wall / 0.02));
  // The figure answered: within the bound, by the crossfade when nothing was ready.
  EXPECT_GE(rig.player.starts(1), 1u);
  EXPECT_EQ(rig.player.current_cue(), 1);
}

TEST(LearnedTransition, TheCycleNeitherAllocatesNorWaitsForTheWorker) {
  Rig rig(true, true, false);
  for (int i = 0; i < 10; ++i) rig.step();
  long allocations = 0;
  int waited = 0;
  {
    test::AllocationCounter counter;
    rig.requests.cue(1);
    // The same cycle time again and again until the frames are there: the
    // figure plays on meanwhile, and each call returns at once.
    const auto begin = std::chrono::steady_clock::now();
    while (rig.player.learned_played() == 0 && rig.player.learned_late() == 0 &&
           std::chrono::steady_clock::now() - begin < std::chrono::seconds(5)) {
      rig.player.sample(rig.t(), rig.out);
      ++waited;
    }
    for (int i = 0; i < 160; ++i, ++rig.k) rig.player.sample(rig.t(), rig.out);  // no copies
    allocations = counter.count();
  }
  EXPECT_EQ(rig.player.learned_played(), 1u);
  EXPECT_GE(waited, 1);
  EXPECT_EQ(allocations, 0);
}

TEST(LearnedTransition, ATransitionLengthenedPastItsBuffersCrossfadesAndIsCounted) {
  // Joints slow enough that the 0.5 rad gap stretches the crossfade to 31 s:
  // 500 frames, past the 64 allocated.
  Rig rig(false, true, true, kDt, 0.1);
  Rig plain(false, false, true, kDt, 0.1);
  for (int i = 0; i < 10; ++i) rig.step(), plain.step();
  rig.requests.cue(1);
  plain.requests.cue(1);
  for (int i = 0; i < 50; ++i) ASSERT_EQ(rig.step(), plain.step()) << "cycle " << i;
  EXPECT_GT(rig.player.last_crossfade_s(), 64 * kFrameS);
  EXPECT_EQ(rig.player.learned_unusable(), 1u);
  EXPECT_EQ(rig.player.learned_played(), 0u);
}

// --- the cue file ---

struct Files {
  fs::path dir = fs::temp_directory_path() / ("learned_transition_" + std::to_string(::getpid()));
  Files() {
    fs::create_directories(dir);
    seqnet::write_model_file((dir / "tiny.model").string(), model());
    std::ofstream(dir / "corrupt.model") << "ANSEQNN\nnot a model at all";
  }
  ~Files() { fs::remove_all(dir); }
  std::string cue_file(const std::string& text) const {
    std::ofstream((dir / "cues.yaml").string()) << text;
    return (dir / "cues.yaml").string();
  }
};

RobotConfig robot(const char* hip = "hip") {
  RobotConfig r;
  r.name = "legs";
  r.joints = joints();
  r.joints[0].name = hip;
  return r;
}

std::string error_of(const Files& f, const std::string& text, const RobotConfig& r = robot()) {
  try {
    load_cues(f.cue_file(text), r);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

const char* kCues =
    "idle: rest\n"
    "cues:\n"
    "  rest: {play: {pose: {hip: 5}}}\n"
    "  reach:\n"
    "    play: {pose: {hip: 30, knee: 20}}\n";

TEST(LearnedTransitionFile, ACueAndTheFilesDefaultTakeALearnedTransition) {
  Files f;
  const LoadedCues own = load_cues(
      f.cue_file(std::string(kCues) +
                 "    transition: {interpolation: learned, model: tiny.model, frame_s: 0.04}\n"),
      robot());
  EXPECT_FALSE(own.cues[0].transition.learned());
  ASSERT_TRUE(own.cues[1].transition.learned());
  EXPECT_EQ(own.cues[1].transition.joints, (std::vector<int>{0, 1}));
  EXPECT_DOUBLE_EQ(own.cues[1].transition.frame_s, 0.04);
  // The tiny model was never measured: the show path's warning, with this line.
  ASSERT_EQ(own.warnings.size(), 1u);
  EXPECT_EQ(own.warnings[0].rfind(f.cue_file("") + ":6: cues.reach.transition.model: ", 0), 0u)
      << own.warnings[0];  // warnings name the line alone, as a show's do
  EXPECT_NE(own.warnings[0].find("never measured against linear interpolation"), std::string::npos);

  const LoadedCues all = load_cues(
      f.cue_file("transition: {interpolation: learned, model: tiny.model, frame_s: 0.04}\n" +
                 std::string(kCues) + "    transition: {interpolation: crossfade}\n"),
      robot());
  EXPECT_TRUE(all.cues[0].transition.learned());
  EXPECT_FALSE(all.cues[1].transition.learned());
  EXPECT_EQ(all.warnings.size(), 1u);
}

TEST(LearnedTransitionFile, ABadTransitionIsRefusedWithItsLineAndKey) {
  Files f;
  const std::string file = f.cue_file("");
  const auto with = [](const std::string& t) {
    return std::string(kCues) + "    transition: " + t + "\n";
  };
  struct Case {
    std::string text;
    std::string where;
    std::string says;
  } cases[] = {
      {with("{interpolation: learned, model: none.model, frame_s: 0.04}"),
       ":6: cues.reach.transition.model: ", "file not found"},
      {with("{interpolation: learned, model: corrupt.model, frame_s: 0.04}"),
       ":6: cues.reach.transition.model: ", "corrupt.model"},
      {with("{interpolation: spline}"),
       ":6: cues.reach.transition.interpolation: ", "expected crossfade or learned"},
      {with("{interpolation: crossfade, model: tiny.model}"),
       ":6: cues.reach.transition.model: ", "only a learned transition"},
      {with("{interpolation: learned, model: tiny.model}"), ":6: cues.reach.transition", "frame_s"},
      {with("{interpolation: learned, model: tiny.model, frame_s: 2}"),
       ":6: cues.reach.transition.frame_s: ", ""},
      {with("{interpolation: learned, model: tiny.model, frame_s: 0.04, blend: 1}"),
       ":6: cues.reach.transition", "blend"},
      {with("{interpolation: learned, model: tiny.model, frame_s: 0.04}") +
           "    crossfade_s: 0.05\n",
       ":7: cues.reach.crossfade_s: ", "at least two of the model's frames"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(f, c.text);
    EXPECT_EQ(e.rfind(file + c.where.substr(0, 3), 0), 0u) << c.text << "\n -> " << e;
    EXPECT_NE(e.find(c.where.substr(3)), std::string::npos) << c.text << "\n -> " << e;
    EXPECT_NE(e.find(c.says), std::string::npos) << c.text << "\n -> " << e;
  }
  // A model of joints the robot does not have.
  RobotConfig other = robot();
  other.joints[1].name = "knees";
  const std::string e = error_of(f,
                                 "idle: rest\n"
                                 "cues:\n"
                                 "  rest: {play: {pose: {hip: 5}}}\n"
                                 "  reach:\n"
                                 "    play: {pose: {hip: 30}}\n"
                                 "    transition: {interpolation: learned, model: tiny.model, "
                                 "frame_s: 0.04}\n",
                                 other);
  EXPECT_EQ(e.rfind(file + ":6:", 0), 0u) << e;
  EXPECT_NE(e.find(" cues.reach.transition.model: "), std::string::npos) << e;
  EXPECT_NE(e.find("moves joint \"knee\""), std::string::npos) << e;
}

}  // namespace
}  // namespace animrt::learned_transition_test
