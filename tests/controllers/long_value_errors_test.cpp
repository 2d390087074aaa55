// A name of thousands of characters in an input file: the error line quotes
// at most kMaxQuotedChars of it, in whichever reader it is refused.

#include <gtest/gtest.h>

#include <string>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/controllers/herd/scene.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "controllers/gait_file_error.hpp"

namespace animrt {
namespace {

const std::string kLong(5000, 'x');

// The longest run of 'x' in `line`: how much of the value it repeats.
std::size_t longest_run(const std::string& line) {
  std::size_t best = 0, run = 0;
  for (char c : line) {
    run = c == 'x' ? run + 1 : 0;
    best = std::max(best, run);
  }
  return best;
}

void expect_short(const std::string& line, const std::string& says) {
  EXPECT_NE(line.find(says), std::string::npos) << line.substr(0, 300);
  EXPECT_LE(longest_run(line), (kMaxQuotedChars + 1) / 2) << line.substr(0, 300);
  EXPECT_LT(line.size(), 400u) << line.substr(0, 300);
}

TEST(LongValueErrors, GaitFileUndefinedCurveAndLimb) {
  const std::string head =
      "name: test\nstride_frequency_hz: 2.0\ncurves:\n  hip: t\nlimbs:\n  a: 0.0\njoints:\n";
  expect_short(gait_file_error(head + "  j1: {curve: " + kLong + ", limb: a}\n"),
               "undefined curve 'xxx");
  expect_short(gait_file_error(head + "  j1: {curve: hip, limb: " + kLong + "}\n"),
               "undefined limb 'xxx");
}

TEST(LongValueErrors, ExpressionUnknownName) {
  try {
    (void)Expression::compile("1 + " + kLong);
    ADD_FAILURE() << "an unknown name compiled";
  } catch (const ExpressionError& e) {
    expect_short(e.what(), "unknown name 'xxx");
  }
}

TEST(LongValueErrors, HerdSceneUnknownFigure) {
  const std::string text = std::string("bounds_m: [-20, -10, 20, 10]\nfigures:\n  pony: {robot: ") +
                           ANIMRT_SOURCE_DIR +
                           "/configs/robots/quadruped.yaml, radius_m: 0.3}\ngroups:\n"
                           "  - {name: red, kind: crowd, figure: " +
                           kLong +
                           ", count: 2, spawn_m: [-18, -8, -14, 8],\n"
                           "     target_m: [16, 0], speed_mps: [0.05, 0.1]}\n";
  try {
    (void)herd::parse_herd_scene(YamlNode::load_string(text, "scene.yaml"));
    ADD_FAILURE() << "an unknown figure loaded";
  } catch (const InputError& e) {
    expect_short(e.what(), "no figure named 'xxx");
  }
}

}  // namespace
}  // namespace animrt
