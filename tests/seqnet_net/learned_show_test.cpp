// A show whose tracks use `interpolation: learned`: the in-betweens come from
// a trained joint-space model when the show is bound, its keys are played
// exactly, and a show that does not fit its model is refused at load.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/learn/seqnet/training.hpp"
#include "net_test_util.hpp"

namespace animrt {
namespace {

// One tiny joint model (hip, knee, ankle; 8-frame windows) for every test.
const std::string& model_path() {
  static const std::string path = [] {
    seqnet::TrainOptions o = nettest::tiny_options(
        nettest::write_joint_csv("learned_show_swing.csv", 120), "learned_show.model");
    o.iterations = 40;
    std::ostringstream log;
    seqnet::train(o, log);
    return o.out;
  }();
  return path;
}

std::vector<JointSpec> joints() {
  std::vector<JointSpec> j(4);
  const char* names[] = {"hip", "knee", "ankle", "tail"};
  for (int i = 0; i < 4; ++i) {
    j[static_cast<std::size_t>(i)].name = names[i];
    j[static_cast<std::size_t>(i)].limits = {deg_to_rad(-90), deg_to_rad(90), 3.0, 30.0};
  }
  return j;
}

std::string write(const std::string& name, const std::string& text) {
  const std::string path = nettest::temp_path(name);
  std::ofstream(path) << text;
  return path;
}

// Keys 10 frames (0.4 s) apart, in degrees.
std::string show_text(const std::string& interpolation, bool loop = false,
                      const std::string& learned = "") {
  const std::string section = !learned.empty() ? learned
                              : interpolation == "learned"
                                  ? "learned: {model: " + model_path() + ", frame_s: 0.04}\n"
                                  : "";
  return std::string("name: learned\n") + (loop ? "loop: true\nduration_s: 1.2\n" : "") + section +
         "joints:\n" + "  hip: {interpolation: " + interpolation +
         ", keys: [[0, 0], [0.4, 20], [0.8, -15]]}\n" + "  knee: {interpolation: " + interpolation +
         ", keys: [[0, 50], [0.4, 40], [0.8, 60]]}\n" +
         "  ankle: {interpolation: " + interpolation + ", keys: [[0, -5], [0.4, 8], [0.8, 2]]}\n" +
         "  tail: {keys: [[0, 0], [0.8, 30]]}\n";
}

std::vector<double> sample(const MotionSource& s, double t) {
  std::vector<double> out(4, -99.0);
  s.sample(t, out);
  return out;
}

std::string error_of(const std::string& text) {
  try {
    load_show_source(write("bad_learned.yaml", text), joints());
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(LearnedShow, KeysArePlayedExactlyAndTheInBetweensAreTheModels) {
  const auto show = load_show_source(write("learned.yaml", show_text("learned")), joints());
  const auto cubic = load_show_source(write("cubic.yaml", show_text("cubic")), joints());

  // What the model completes from the same keys, in its joint order.
  const seqnet::ModelFile file = seqnet::read_model_file(model_path());
  seqnet::SeqNetInference net(file, model_path());
  seqnet::FrameMatrix keys(3, 3);
  keys << deg_to_rad(0), deg_to_rad(20), deg_to_rad(-15),  //
      deg_to_rad(50), deg_to_rad(40), deg_to_rad(60),      //
      deg_to_rad(-5), deg_to_rad(8), deg_to_rad(2);
  const seqnet::Completion done = net.complete(keys, {9, 9});
  ASSERT_EQ(done.frames.cols(), 21);

  double largest_departure = 0.0;
  for (int f = 0; f <= 20; ++f) {
    const double t = 0.04 * f;
    const std::vector<double> learned = sample(*show, t);
    for (int j = 0; j < 3; ++j) {
      const double expected = std::clamp(done.frames(j, f), deg_to_rad(-90), deg_to_rad(90));
      EXPECT_NEAR(learned[static_cast<std::size_t>(j)], expected, 1e-12) << "frame " << f;
      largest_departure =
          std::max(largest_departure, std::abs(learned[static_cast<std::size_t>(j)] -
                                               sample(*cubic, t)[static_cast<std::size_t>(j)]));
    }
    // The tail keeps its own (cubic) interpolation.
    EXPECT_DOUBLE_EQ(learned[3], sample(*cubic, t)[3]);
  }
  // Keys bit for bit.
  EXPECT_EQ(sample(*show, 0.4)[0], deg_to_rad(20));
  EXPECT_EQ(sample(*show, 0.8)[1], deg_to_rad(60));
  // The model's in-betweens are not the cubic ones.
  EXPECT_GT(largest_departure, deg_to_rad(0.5));
}

TEST(LearnedShow, ALoopingShowCompletesTheWrapToItsFirstKey) {
  const auto show = load_show_source(write("loop.yaml", show_text("learned", true)), joints());
  // 0.8 s -> 1.2 s (= 0 s) is a 9-frame gap completed by the model: between
  // the last key and the first, and back to the first key at the wrap.
  EXPECT_DOUBLE_EQ(sample(*show, 1.2)[0], deg_to_rad(0));
  EXPECT_DOUBLE_EQ(sample(*show, 0.8)[0], deg_to_rad(-15));
  const double mid = sample(*show, 1.0)[0];
  EXPECT_TRUE(std::isfinite(mid));
  EXPECT_NE(mid, sample(*show, 0.8)[0]);
}

TEST(LearnedShow, AShowThatDoesNotFitItsModelIsRefusedAtLoad) {
  // Another joint set: the learned tracks are hip and knee only.
  std::string text = show_text("learned");
  text.replace(text.find("ankle: {interpolation: learned"), 30, "ankle: {interpolation: cubic  ");
  EXPECT_NE(error_of(text).find("lacks ankle"), std::string::npos) << error_of(text);

  // Key times differ.
  text = show_text("learned");
  text.replace(text.find("[0.4, 8]"), 8, "[0.5, 8]");
  EXPECT_NE(error_of(text).find("share their key times"), std::string::npos) << error_of(text);

  // A gap that is not whole frames.
  EXPECT_NE(error_of(show_text("learned", false,
                               "learned: {model: " + model_path() + ", frame_s: 0.03}\n"))
                .find("not a whole number"),
            std::string::npos);

  // No learned section.
  std::string missing = show_text("learned");
  missing.erase(missing.find("learned: {"), missing.find("joints:") - missing.find("learned: {"));
  EXPECT_NE(error_of(missing).find("needs a `learned"), std::string::npos) << error_of(missing);

  // `learned` on one key.
  text = show_text("cubic");
  text.replace(text.find("[0.4, 20]"), 9, "{t: 0.4, value: 20, interpolation: learned}");
  EXPECT_NE(error_of(text).find("whole track"), std::string::npos) << error_of(text);

  // A corrupt model names the show's key and the model file.
  const std::string corrupt = write("corrupt.model", "ANSEQNN\n garbage");
  const std::string message =
      error_of(show_text("learned", false, "learned: {model: " + corrupt + ", frame_s: 0.04}\n"));
  EXPECT_NE(message.find("bad_learned.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("learned.model"), std::string::npos) << message;
  EXPECT_NE(message.find("corrupt.model"), std::string::npos) << message;
}

}  // namespace
}  // namespace animrt
