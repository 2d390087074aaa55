// A head motion whose sound file is bad: the error names the robot file's
// line and key that chose the sound, with the sound's own problem, as a
// show's audio.file does (it used to name only the WAV).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_loader.hpp"

namespace animrt::head_audio_error_test {
namespace {

namespace fs = std::filesystem;
const std::string kRoot = ANIMRT_SOURCE_DIR;

// The bundled head robot with its sound replaced by `audio`, in a folder of
// its own (the other files it names by absolute paths).
std::string head_robot(const std::string& name, const std::string& audio) {
  std::ifstream in(kRoot + "/configs/robots/head.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = std::regex_replace(text, std::regex("\\.\\./head/model\\.txt"),
                            kRoot + "/configs/head/model.txt");
  text = std::regex_replace(text, std::regex("\\.\\./head/utterance\\.wav"), audio);
  text = std::regex_replace(text, std::regex("\\.\\./models/head\\.xml"),
                            kRoot + "/configs/models/head.xml");
  const fs::path path = fs::path(::testing::TempDir()) / (name + ".yaml");
  std::ofstream(path) << text;
  return path.string();
}

TEST(HeadAudioError, ASoundThatIsNotAudioIsRefusedAtTheRobotFilesLineAndKey) {
  const fs::path wav = fs::path(::testing::TempDir()) / "head_audio_text.wav";
  std::ofstream(wav) << "hello this is not audio\n";
  const std::string robot = head_robot("head_audio_text", wav.string());
  try {
    (void)load_robot(robot);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, robot);
    EXPECT_EQ(e.where().line, 52);
    EXPECT_EQ(e.key(), "motion.audio");
    const std::string want = "audio file \"" + wav.string() + "\": not a readable audio file";
    EXPECT_EQ(e.message().substr(0, want.size()), want) << e.what();
  }
}

}  // namespace
}  // namespace animrt::head_audio_error_test
