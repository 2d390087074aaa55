// A looping show's key at duration_s and its key at 0 s are one instant of
// the loop: with two values the joint jumped there on every pass (10 deg
// to 0 in 80 ms, as fast as the safety filter let it).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/controllers/show/show_file.hpp"
#include "animrt/core/error.hpp"

namespace animrt::show_loop_wrap_test {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::string& text) {
  const fs::path path = fs::temp_directory_path() / "animrt_loop_wrap.yaml";
  std::ofstream(path) << text;
  try {
    (void)load_show_file(path.string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ShowLoopWrap, TwoValuesAtTheLoopsOneInstantAreRefused) {
  const std::string jump = error_of(
      "name: a\nloop: true\nduration_s: 2\njoints:\n  jaw: {keys: [[0, 0], [1, 5], [2, 10]]}\n");
  EXPECT_NE(jump.find(":5:"), std::string::npos) << jump;
  EXPECT_NE(jump.find("joints.jaw.keys: the key at 2 s (10) and the first at 0 s (0) are one "
                      "instant of the loop"),
            std::string::npos)
      << jump;
  // The same value closes the loop; a last key before duration_s, or a
  // first one after 0, leaves a segment to walk between them.
  EXPECT_EQ(error_of("name: a\nloop: true\nduration_s: 2\njoints:\n"
                     "  jaw: {keys: [[0, 0], [1, 5], [2, 0]]}\n"),
            "");
  EXPECT_EQ(error_of("name: a\nloop: true\nduration_s: 2.5\njoints:\n"
                     "  jaw: {keys: [[0, 0], [1, 5], [2, 10]]}\n"),
            "");
  EXPECT_EQ(error_of("name: a\nloop: true\nduration_s: 2\njoints:\n"
                     "  jaw: {keys: [[0.5, 0], [1, 5], [2, 10]]}\n"),
            "");
  // Not looping, nothing wraps.
  EXPECT_EQ(error_of("name: a\nduration_s: 2\njoints:\n  jaw: {keys: [[0, 0], [2, 10]]}\n"), "");
}

}  // namespace
}  // namespace animrt::show_loop_wrap_test
