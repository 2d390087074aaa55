// Keyframe shows: interpolation, continuity, looping, layering, validation,
// and no allocation in sample().

#include <gtest/gtest.h>
#include <sndfile.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/joint.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

// More time than any wind-down asks for: the stop deadline does not cut it.
constexpr double kShowAmpleS = 100.0;

std::string write(const std::string& name, const std::string& text) {
  const std::string path =
      ::testing::TempDir() + "/" +
      std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

std::vector<JointSpec> joints() {
  std::vector<JointSpec> j(3);
  const char* names[] = {"neck", "jaw", "eye"};
  for (int i = 0; i < 3; ++i) {
    j[i].name = names[i];
    j[i].limits = {deg_to_rad(-45), deg_to_rad(45), 3.0, 30.0};
  }
  return j;
}

std::string error_of(const std::string& text) {
  try {
    load_show_source(write("bad_show.yaml", text), joints());
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

double deg_at(const MotionSource& s, double t, int joint) {
  std::vector<double> targets(3, -99.0);
  s.sample(t, targets);
  return rad_to_deg(targets[static_cast<std::size_t>(joint)]);
}

const std::string kShow = R"(name: test
joints:
  jaw:
    interpolation: linear
    keys:
      - [0, 0]
      - {t: 1, value: 10, interpolation: step}
      - [2, 20]
      - [3, 0]
  eye:
    keys:
      - [0, 0]
      - [1, 10]
      - [2, 0]
      - [4, 30]
)";

TEST(Show, StepLinearAndCubicSegments) {
  auto s = load_show_source(write("show.yaml", kShow), joints());
  ASSERT_EQ(s->driven_joints().size(), 2u);
  EXPECT_DOUBLE_EQ(deg_at(*s, 0.5, 1), 5.0);                // linear
  EXPECT_DOUBLE_EQ(deg_at(*s, 1.5, 1), 10.0);               // step holds the key
  EXPECT_DOUBLE_EQ(deg_at(*s, 2.5, 1), 10.0);               // linear 20 -> 0
  EXPECT_DOUBLE_EQ(deg_at(*s, 9.0, 1), 0.0);                // past the end: hold the last key
  EXPECT_DOUBLE_EQ(deg_at(*s, 0.5, 0), rad_to_deg(-99.0));  // a joint the show does not drive
  // Cubic through the keys, zero slope at the ends, slope (0-0)/2 = 0 at t=1.
  EXPECT_NEAR(deg_at(*s, 1.0, 2), 10.0, 1e-12);
  EXPECT_NEAR(deg_at(*s, 0.5, 2), 5.0, 1e-12);  // both slopes 0: the midpoint
  EXPECT_NEAR(deg_at(*s, 4.0, 2), 30.0, 1e-12);
}

TEST(Show, CubicVelocityIsContinuousAcrossKeys) {
  auto s = load_show_source(write("show.yaml", kShow), joints());
  const double h = 1e-6;
  for (double key : {1.0, 2.0}) {
    const double left = (deg_at(*s, key, 2) - deg_at(*s, key - h, 2)) / h;
    const double right = (deg_at(*s, key + h, 2) - deg_at(*s, key, 2)) / h;
    EXPECT_NEAR(left, right, 1e-3) << "at t=" << key;
  }
  // Slope at t=2 is (30 - 10) / (4 - 1) deg/s.
  EXPECT_NEAR((deg_at(*s, 2.0 + h, 2) - deg_at(*s, 2.0 - h, 2)) / (2 * h), 20.0 / 3.0, 1e-3);
}

TEST(Show, LoopingWrapsSmoothly) {
  std::string text = kShow;
  text.replace(text.find("name: test\n"), 11, "name: test\nloop: true\nduration_s: 5\n");
  auto s = load_show_source(write("loop.yaml", text), joints());
  EXPECT_NEAR(deg_at(*s, 5.5, 2), deg_at(*s, 0.5, 2), 1e-9);
  EXPECT_NEAR(deg_at(*s, 10.0, 2), 0.0, 1e-9);
  // Wrap segment 4 s (30) -> 5 s (0): continuous at the wrap and at t=4.
  const double h = 1e-6;
  EXPECT_NEAR(deg_at(*s, 5.0 - h, 2), deg_at(*s, 5.0, 2), 1e-3);
  const double left = (deg_at(*s, 4.0, 2) - deg_at(*s, 4.0 - h, 2)) / h;
  const double right = (deg_at(*s, 4.0 + h, 2) - deg_at(*s, 4.0, 2)) / h;
  EXPECT_NEAR(left, right, 1e-3);
}

TEST(Show, ThePlayheadPausesSeeksAndWrapsALoopingShow) {
  std::string text = kShow;
  text.replace(text.find("name: test\n"), 11, "name: test\nloop: true\nduration_s: 5\n");
  auto s = load_show_source(write("loop.yaml", text), joints());
  ShowPosition p = s->show_position(7.0);
  EXPECT_TRUE(p.show);
  EXPECT_TRUE(p.playing);
  EXPECT_DOUBLE_EQ(p.position_s, 2.0);  // wrapped
  EXPECT_DOUBLE_EQ(p.duration_s, 5.0);

  // Paused at motion time 1.5: the show stays at 1.5 s whatever the time.
  s->control(ShowCommand{false, 0, 0.0}, 1.5);
  EXPECT_FALSE(s->show_position(9.0).playing);
  EXPECT_DOUBLE_EQ(s->show_position(9.0).position_s, 1.5);
  EXPECT_DOUBLE_EQ(deg_at(*s, 9.0, 2), deg_at(*s, 1.5, 2));
  // A seek while paused moves the held time (clamped to the show).
  s->control(ShowCommand{false, 1, 3.25}, 9.0);
  EXPECT_DOUBLE_EQ(s->show_position(20.0).position_s, 3.25);
  s->control(ShowCommand{false, 2, 99.0}, 9.0);
  EXPECT_DOUBLE_EQ(s->show_position(20.0).position_s, 0.0);  // a loop's end is its start
  s->control(ShowCommand{false, 3, 3.25}, 9.0);
  // Play at motion time 10: on from 3.25 s.
  s->control(ShowCommand{true, 3, 3.25}, 10.0);
  EXPECT_NEAR(s->show_position(10.5).position_s, 3.75, 1e-12);
  // A seek while playing.
  s->control(ShowCommand{true, 4, 1.0}, 11.0);
  EXPECT_NEAR(s->show_position(11.25).position_s, 1.25, 1e-12);
  EXPECT_TRUE(s->show_position(11.25).playing);
}

TEST(Show, ANonLoopingShowEndsAndPlaysAgainFromItsStart) {
  auto s = load_show_source(write("show.yaml", kShow), joints());
  const double end = s->show_position(0.0).duration_s;
  ASSERT_GT(end, 0.0);
  EXPECT_FALSE(s->show_position(end + 1.0).playing);
  EXPECT_DOUBLE_EQ(s->show_position(end + 1.0).position_s, end);
  s->control(ShowCommand{true, 0, 0.0}, end + 1.0);
  EXPECT_TRUE(s->show_position(end + 1.5).playing);
  EXPECT_DOUBLE_EQ(s->show_position(end + 1.5).position_s, 0.5);
}

TEST(Show, LayersPassTheTransportToTheirShows) {
  std::vector<std::unique_ptr<MotionSource>> layers;
  layers.push_back(load_show_source(write("a.yaml", kShow), joints()));
  layers.push_back(load_show_source(write("b.yaml", kShow), joints()));
  auto s = make_layered_source(std::move(layers));
  EXPECT_TRUE(s->show_position(0.0).show);
  s->control(ShowCommand{false, 1, 0.5}, 2.0);
  EXPECT_DOUBLE_EQ(s->show_position(3.0).position_s, 0.5);
  EXPECT_FALSE(s->show_position(3.0).playing);
  // Both layers hold: every joint is at its 0.5 s value.
  std::vector<double> at_half(3), now(3);
  auto plain = load_show_source(write("c.yaml", kShow), joints());
  plain->sample(0.5, at_half);
  s->sample(3.0, now);
  EXPECT_EQ(now, at_half);
}

// A layer that counts the clock handovers it gets.
class ClockCounter final : public MotionSource {
 public:
  std::span<const int> driven_joints() const override { return {}; }
  void sample(double, std::span<double>) const override {}
  void start(const MotionClock& clock) override {
    ++starts;
    start_ns = clock.start;
  }
  void stop() override { ++stops; }
  void steer(const MotionCommand& command) override { steered = command; }
  void sense(const Sensors& sensors) override { sensed = &sensors; }
  double wind_down(double t, double granted_s) override {
    wound_at = t;
    return std::min(wind, granted_s);
  }
  int starts = 0, stops = 0;
  Nanos start_ns = -1;
  double wind = 0.0;  // what wind_down() asks for (s)
  double wound_at = -1.0;
  MotionCommand steered{-1.0, -1.0};
  const Sensors* sensed = nullptr;
};

// Two recording layers around a show layer, as a walk under a show's head
// moves is layered; `a` and `b` point at the recording ones.
struct ThreeLayers {
  ClockCounter* a = nullptr;
  ClockCounter* b = nullptr;
  std::unique_ptr<MotionSource> source;
  ThreeLayers(const std::string& show_file, double wind_a = 0.0, double wind_b = 0.0) {
    std::vector<std::unique_ptr<MotionSource>> layers;
    auto first = std::make_unique<ClockCounter>();
    auto last = std::make_unique<ClockCounter>();
    first->wind = wind_a;
    last->wind = wind_b;
    a = first.get();
    b = last.get();
    layers.push_back(std::move(first));
    layers.push_back(load_show_source(write(show_file, kShow), joints()));
    layers.push_back(std::move(last));
    source = make_layered_source(std::move(layers));
  }
};

// The herd's or the dashboard's steering, and the cycle's sensor readings,
// reach every layer (a steered walk under a show's head moves).
TEST(Show, LayersPassSteeringAndSensorsToEveryLayer) {
  ThreeLayers l("st.yaml");
  const auto& s = l.source;
  ClockCounter* pa = l.a;
  ClockCounter* pb = l.b;
  s->steer(MotionCommand{0.3, -0.2});
  const Sensors sensors{};
  s->sense(sensors);
  for (const ClockCounter* c : {pa, pb}) {
    EXPECT_DOUBLE_EQ(c->steered.speed_m_s, 0.3);
    EXPECT_DOUBLE_EQ(c->steered.turn_rad_s, -0.2);
    EXPECT_EQ(c->sensed, &sensors);
  }
}

// A stop winds every layer down at once (a walk under a show): the layered
// source asks for the longest, and a show layer asks for none.
TEST(Show, LayersWindDownTogetherForAsLongAsTheSlowestAsks) {
  ThreeLayers l("w.yaml", 1.5, 2.5);
  const auto& s = l.source;
  ClockCounter* pa = l.a;
  ClockCounter* pb = l.b;
  EXPECT_DOUBLE_EQ(s->wind_down(4.0, kShowAmpleS), 2.5);
  EXPECT_DOUBLE_EQ(pa->wound_at, 4.0);
  EXPECT_DOUBLE_EQ(pb->wound_at, 4.0);
  EXPECT_DOUBLE_EQ(load_show_source(write("w2.yaml", kShow), joints())->wind_down(4.0, kShowAmpleS),
                   0.0);
}

TEST(Show, LayersPassTheRunsClockToEveryLayer) {
  ThreeLayers l("d.yaml");
  const auto& s = l.source;
  ClockCounter* pa = l.a;
  ClockCounter* pb = l.b;
  const ManualClock clock(7);
  s->start(MotionClock{&clock, 42, true});
  s->stop();
  for (const ClockCounter* c : {pa, pb}) {
    EXPECT_EQ(c->starts, 1);
    EXPECT_EQ(c->start_ns, 42);
    EXPECT_EQ(c->stops, 1);
  }
}

TEST(Show, SampleDoesNotAllocate) {
  auto s = load_show_source(write("show.yaml", kShow), joints());
  std::vector<double> targets(3);
  test::AllocationCounter counter;
  for (int k = 0; k < 1000; ++k) s->sample(k * 0.01, targets);
  EXPECT_EQ(counter.count(), 0);
}

TEST(Show, LayersLetTheLaterSourceWin) {
  auto under = load_show_source(
      write("under.yaml", "joints:\n  neck: {keys: [[0, 5]]}\n  jaw: {keys: [[0, 7]]}\n"),
      joints());
  auto over = load_show_source(write("over.yaml", "joints:\n  jaw: {keys: [[0, 3]]}\n"), joints());
  std::vector<std::unique_ptr<MotionSource>> layers;
  layers.push_back(std::move(under));
  layers.push_back(std::move(over));
  auto s = make_layered_source(std::move(layers));
  EXPECT_EQ(s->driven_joints().size(), 2u);
  EXPECT_DOUBLE_EQ(deg_at(*s, 1.0, 0), 5.0);
  EXPECT_DOUBLE_EQ(deg_at(*s, 1.0, 1), 3.0);
}

TEST(Show, AudioTrackWithOffset) {
  const std::string wav = ::testing::TempDir() + "/hello.wav";
  SF_INFO info{};
  info.samplerate = 8000;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* f = sf_open(wav.c_str(), SFM_WRITE, &info);
  ASSERT_NE(f, nullptr);
  std::vector<short> samples(800, 0);
  sf_write_short(f, samples.data(), static_cast<sf_count_t>(samples.size()));
  sf_close(f);
  const ShowFile show = load_show_file(
      write("audio.yaml",
            "audio: {file: hello.wav, offset_s: 0.25}\njoints:\n  jaw: {keys: [[0, 1]]}\n"));
  EXPECT_TRUE(show.has_audio);
  EXPECT_TRUE(std::filesystem::equivalent(show.audio.file, wav));
  EXPECT_DOUBLE_EQ(show.audio.offset_s, 0.25);
  std::ofstream(::testing::TempDir() + "/not_audio.wav") << "garbage";
  const std::string e =
      error_of("audio: {file: not_audio.wav}\njoints:\n  jaw: {keys: [[0, 1]]}\n");
  EXPECT_NE(e.find("bad_show.yaml:1:15: audio.file: cannot open audio file"), std::string::npos)
      << e;
}

// Values are in the joint's unit: metres for a prismatic joint, degrees for
// a revolute one, in the same show.
TEST(Show, PrismaticJointKeysAreMetres) {
  std::vector<JointSpec> j = joints();
  JointSpec slide;
  slide.name = "slide";
  slide.type = JointType::prismatic;
  slide.limits = {0.0, 0.1, 0.05, 0.5};
  j.push_back(slide);
  const std::string text =
      "joints:\n"
      "  slide: {interpolation: linear, keys: [[0, 0.02], [1, 0.08]]}\n"
      "  jaw: {unit: deg, interpolation: linear, keys: [[0, 0], [1, 10]]}\n";
  auto source = load_show_source(write("metres.yaml", text), j);
  std::vector<double> targets(4, -1.0);
  source->sample(0.5, targets);
  EXPECT_NEAR(targets[3], 0.05, 1e-12);
  EXPECT_NEAR(targets[1], deg_to_rad(5.0), 1e-12);
  // The same track stated in metres explicitly.
  auto explicit_unit =
      load_show_source(write("unit_m.yaml", "joints:\n  slide: {unit: m, keys: [[0, 0.07]]}\n"), j);
  explicit_unit->sample(0.0, targets);
  EXPECT_NEAR(targets[3], 0.07, 1e-12);

  auto error_with = [&](const std::string& show) {
    try {
      load_show_source(write("bad_metres.yaml", show), j);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string e = error_with("joints:\n  slide: {unit: deg, keys: [[0, 0.05]]}\n");
  EXPECT_NE(e.find("bad_metres.yaml:2:17: joints.slide.unit: unit deg, but joint 'slide' is "
                   "prismatic (its limits are in metres); use unit: m"),
            std::string::npos)
      << e;
  // Degrees written for a slide are far outside its stroke, and said in metres.
  e = error_with("joints:\n  slide: {keys: [[0, 0.05], [1, 30]]}\n");
  EXPECT_NE(e.find("joints.slide.keys: key at 1 s is 30 m, outside the joint's limits 0..0.1 m"),
            std::string::npos)
      << e;
}

TEST(Show, ErrorsNameFileLineAndKey) {
  EXPECT_NE(error_of("joints:\n  jaw:\n    keys:\n      - [0, 0]\n      - [0, 5]\n")
                .find("bad_show.yaml:5:10: joints.jaw.keys[1][0]: expected a time after the "
                      "previous key's 0 s"),
            std::string::npos)
      << error_of("joints:\n  jaw:\n    keys:\n      - [0, 0]\n      - [0, 5]\n");
  EXPECT_NE(error_of("joints:\n  jaw: {interpolation: spline, keys: [[0, 0]]}\n")
                .find("joints.jaw.interpolation: expected step, linear, cubic or learned, found "
                      "\"spline\""),
            std::string::npos);
  EXPECT_NE(
      error_of("joints:\n  tail: {keys: [[0, 0]]}\n").find("no joint named 'tail' in the robot"),
      std::string::npos);
  EXPECT_NE(error_of("joints:\n  jaw: {keys: [[0, 0], [1, 50]]}\n")
                .find("key at 1 s is 50 deg, outside the joint's limits -45..45 deg"),
            std::string::npos)
      << error_of("joints:\n  jaw: {keys: [[0, 0], [1, 50]]}\n");
  EXPECT_NE(error_of("joints:\n  jaw: {unit: m, keys: [[0, 0]]}\n")
                .find("bad_show.yaml:2:15: joints.jaw.unit: unit m, but joint 'jaw' is revolute "
                      "(its limits are in degrees); use unit: deg"),
            std::string::npos)
      << error_of("joints:\n  jaw: {unit: m, keys: [[0, 0]]}\n");
  EXPECT_NE(error_of("joints:\n  jaw: {unit: inch, keys: [[0, 0]]}\n")
                .find("joints.jaw.unit: expected deg (revolute joint) or m (prismatic joint)"),
            std::string::npos);
  EXPECT_NE(error_of("duration_s: 1\njoints:\n  jaw: {keys: [[0, 0], [2, 1]]}\n")
                .find("duration_s: expected at least the last key's time (2 s)"),
            std::string::npos);
}

}  // namespace
}  // namespace animrt
