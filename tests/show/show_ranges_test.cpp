// A show's lengths are bounded, and a learned track is finite: a model that
// computes inf (clamped to a limit unnoticed before) is refused like NaN.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"
#include "seqnet/tiny_joint_model.hpp"

namespace animrt {
namespace {
namespace show_ranges_test {

namespace fs = std::filesystem;

class ShowRanges : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / "show_ranges";
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
    seqnet::write_model_file((dir / "small.model").string(), seqnet::test::tiny_joint_model(0.1F));
    seqnet::write_model_file((dir / "huge.model").string(), seqnet::test::tiny_joint_model(3e38F));
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string write(const std::string& text) const {
    std::ofstream(dir / "show.yaml") << text;
    return (dir / "show.yaml").string();
  }
  std::string error_of(const std::string& text) const {
    try {
      (void)load_show_file(write(text));
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string at(const std::string& rest) const {
    return (dir / "show.yaml").string() + ":" + rest;
  }
};

// Line 2 is the learned section (line 4 when looping); keys 0.4 s apart.
std::string learned_show(const std::string& model, const std::string& frame_s = "0.04",
                         const std::string& loop_s = "") {
  return "name: s\n" + (loop_s.empty() ? "" : "loop: true\nduration_s: " + loop_s + "\n") +
         "learned: {model: " + model + ", frame_s: " + frame_s +
         "}\n"
         "joints:\n"
         "  hip: {interpolation: learned, keys: [[0, 0], [0.4, 20], [0.8, -15]]}\n"
         "  knee: {interpolation: learned, keys: [[0, 10], [0.4, 5], [0.8, 30]]}\n";
}

std::vector<JointSpec> joints() {
  std::vector<JointSpec> j(2);
  j[0].name = "hip";
  j[1].name = "knee";
  for (auto& x : j) x.limits = {deg_to_rad(-90), deg_to_rad(90), 3.0, 30.0};
  return j;
}

TEST_F(ShowRanges, DurationAndLearnedFramesJustPastTheirBoundsAreRefused) {
  EXPECT_EQ(error_of("name: s\nduration_s: 1e6\njoints: {j: {keys: [[0, 1]]}}\n"), "no error");
  EXPECT_EQ(error_of("name: s\nduration_s: 1.000001e6\njoints: {j: {keys: [[0, 1]]}}\n"),
            at("2:13: duration_s: expected at most 1e+06 s, found \"1.000001e6\""));
  EXPECT_EQ(error_of(learned_show("small.model")), "no error");
  EXPECT_EQ(error_of(learned_show("small.model", "0.0009")),
            at("2:40: learned.frame_s: expected a number from 0.001 to 1, found \"0.0009\""));
  EXPECT_EQ(error_of(learned_show("small.model", "1.2")),
            at("2:40: learned.frame_s: expected a number from 0.001 to 1, found \"1.2\""));
  // A looping show completes its whole duration: 4000 s of 0.04 s frames
  // (100000) load, one more frame does not.
  EXPECT_EQ(error_of(learned_show("small.model", "0.04", "4000")), "no error");
  const std::string long_show = error_of(learned_show("small.model", "0.04", "4000.04"));
  EXPECT_EQ(long_show.rfind(at("4:40: learned.frame_s: the learned tracks span 4000.04 s"), 0), 0u)
      << long_show;
}

TEST_F(ShowRanges, AModelThatComputesInfIsRefusedAtTheShowsModelKey) {
  const std::string e = error_of(learned_show("huge.model"));
  EXPECT_EQ(e.rfind(at("2:18: learned.model: "), 0), 0u) << e;
  EXPECT_NE(e.find((dir / "huge.model").string()), std::string::npos) << e;
  EXPECT_NE(e.find("not finite"), std::string::npos) << e;
}

TEST_F(ShowRanges, AnInfLearnedTrackIsRefusedWhenTheShowIsBound) {
  // A show read with a sound model, then given one that overflows: the
  // completion's inf must not be clamped into a limit and played.
  ShowFile show = load_show_file(write(learned_show("small.model")));
  EXPECT_NO_THROW(make_show_source(show, joints()));
  show.learned.model = std::make_shared<const seqnet::ModelFile>(
      seqnet::read_model_file((dir / "huge.model").string()));
  try {
    (void)make_show_source(show, joints());
    FAIL() << "an inf learned track was played";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().line, 4) << e.what();
    EXPECT_NE(e.message().find("a learned track must be finite"), std::string::npos) << e.what();
  }
}

}  // namespace show_ranges_test
}  // namespace
}  // namespace animrt
