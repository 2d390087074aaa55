// Editing a robot file's values in place: the bytes outside the edited value
// stay as they were, comments and layout included.

#include "animrt/runtime/yaml_value_editor.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace animrt {
namespace {

const std::string kRobot =
    "# A robot.\n"
    "name: bot   # its name\n"
    "\n"
    "joints:\n"
    "  hip:\n"
    "    limits: {min_deg: -45, max_deg: 45, velocity_dps: 300}  # flow\n"
    "    home_deg: 0      # where it rests\n"
    "    actuator:\n"
    "      bus: legs\n"
    "      zero_ticks: 2048 # mid range\n"
    "      direction: 1\n"
    "\n"
    "  # the knee follows\n"
    "  knee:\n"
    "    limits: {min_deg: -60,max_deg: 60}\n"
    "    actuator: {bus: legs, id: 2, zero_ticks: \"2048\"}\n"
    "motion:\n"
    "  type: gait\n";

TEST(YamlValueEditor, ReplacesABlockValueAndKeepsEverythingElse) {
  YamlValueEditor edit(kRobot, "bot.yaml");
  edit.set({"joints", "hip", "actuator", "zero_ticks"}, "1871");
  std::string expected = kRobot;
  expected.replace(expected.find("2048 # mid"), 4, "1871");
  EXPECT_EQ(edit.text(), expected);
}

TEST(YamlValueEditor, ReplacesFlowValuesOfAnyLength) {
  YamlValueEditor edit(kRobot, "bot.yaml");
  edit.set({"joints", "hip", "limits", "min_deg"}, "-38.5");
  edit.set({"joints", "hip", "limits", "max_deg"}, "7");
  edit.set({"joints", "knee", "limits", "min_deg"}, "-59.9");
  edit.set({"joints", "knee", "actuator", "zero_ticks"}, "100");
  std::string expected = kRobot;
  expected.replace(expected.find("{min_deg: -45, max_deg: 45"), 26, "{min_deg: -38.5, max_deg: 7");
  expected.replace(expected.find("{min_deg: -60,"), 14, "{min_deg: -59.9,");
  expected.replace(expected.find("\"2048\""), 6, "100");
  EXPECT_EQ(edit.text(), expected);
}

TEST(YamlValueEditor, AddsAMissingKeyToAFlowMap) {
  YamlValueEditor edit(kRobot, "bot.yaml");
  edit.set({"joints", "knee", "actuator", "direction"}, "-1");
  std::string expected = kRobot;
  expected.replace(expected.find("zero_ticks: \"2048\"}"), 19,
                   "zero_ticks: \"2048\", direction: -1}");
  EXPECT_EQ(edit.text(), expected);
  YamlValueEditor empty("a: {}\n", "e.yaml");
  empty.set({"a", "b"}, "1");
  EXPECT_EQ(empty.text(), "a: {b: 1}\n");
}

TEST(YamlValueEditor, AddsAMissingKeyToABlockMapAfterItsLastEntry) {
  YamlValueEditor edit(kRobot, "bot.yaml");
  edit.set({"joints", "hip", "actuator", "model"}, "XM430");
  edit.set({"joints", "knee", "home_deg"}, "5");
  std::string expected = kRobot;
  expected.insert(expected.find("      direction: 1\n") + 19, "      model: XM430\n");
  expected.insert(expected.find("motion:"), "    home_deg: 5\n");
  EXPECT_EQ(edit.text(), expected);
  // At the end of a file without a final newline.
  YamlValueEditor last("a:\n  b: 1", "e.yaml");
  last.set({"a", "c"}, "2");
  EXPECT_EQ(last.text(), "a:\n  b: 1\n  c: 2\n");
}

TEST(YamlValueEditor, RefusesWhatItCannotEditInPlace) {
  YamlValueEditor edit(kRobot, "bot.yaml");
  // A missing map on the way.
  try {
    edit.set({"joints", "ankle", "home_deg"}, "1");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, "bot.yaml");
    EXPECT_EQ(e.key(), "joints.ankle");
    EXPECT_GT(e.where().line, 0);
  }
  // A map where a value is expected, a value that is not a plain scalar.
  EXPECT_THROW(edit.set({"joints", "hip", "limits"}, "1"), InputError);
  EXPECT_THROW(edit.set({"name"}, "a # b"), InputError);
  EXPECT_THROW(edit.set({"name"}, "a, b"), InputError);
  // A multi-line or tagged value.
  YamlValueEditor folded("a: >\n  one\n  two\nb: !!str 3\n", "f.yaml");
  EXPECT_THROW(folded.set({"a"}, "1"), InputError);
  EXPECT_THROW(folded.set({"b"}, "1"), InputError);
  EXPECT_EQ(edit.text(), kRobot);
}

class ReplaceFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(::testing::TempDir()) /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "robot.yaml").string();
    std::ofstream(path_) << kRobot;
  }
  std::filesystem::path dir_;
  std::string path_;
};

TEST_F(ReplaceFile, ReplacesTheFileAndLeavesNoTemporary) {
  ::chmod(path_.c_str(), 0640);
  replace_file_contents(path_, kRobot, "new: 1\n");
  EXPECT_EQ(read_whole_file(path_), "new: 1\n");
  EXPECT_FALSE(std::filesystem::exists(path_ + ".tmp"));
  struct stat st {};
  ASSERT_EQ(::stat(path_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
}

TEST_F(ReplaceFile, RefusesAFileChangedOnDisk) {
  std::ofstream(path_, std::ios::app) << "# edited meanwhile\n";
  try {
    replace_file_contents(path_, kRobot, "new: 1\n");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("changed on disk"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_whole_file(path_), kRobot + "# edited meanwhile\n");
  EXPECT_FALSE(std::filesystem::exists(path_ + ".tmp"));
}

TEST_F(ReplaceFile, RefusesAReadOnlyFile) {
  ::chmod(path_.c_str(), 0444);
  try {
    replace_file_contents(path_, kRobot, "new: 1\n");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("read-only"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_whole_file(path_), kRobot);
}

}  // namespace
}  // namespace animrt
