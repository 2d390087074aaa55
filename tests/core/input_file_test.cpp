// Input files: only regular files under the size limit are read.

#include "animrt/core/input_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

namespace fs = std::filesystem;

class InputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("animrt_input_file_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  static std::string error_of(const std::string& file, std::uintmax_t max_bytes) {
    try {
      (void)read_input_file(file, max_bytes);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }

  fs::path dir_;
};

TEST_F(InputFileTest, ReadsARegularFileWhole) {
  const std::string text(100000, 'x');
  std::ofstream(path("a.txt"), std::ios::binary) << text << "end";
  EXPECT_EQ(read_input_file(path("a.txt")), text + "end");
  EXPECT_EQ(input_file_problem(path("a.txt")), "");
}

TEST_F(InputFileTest, DirectoryFifoDeviceAndMissingFileEachHaveTheirMessage) {
  EXPECT_EQ(error_of(dir_.string(), kMaxInputFileBytes), dir_.string() + ": is a directory");
  ASSERT_EQ(::mkfifo(path("pipe").c_str(), 0600), 0);
  // Nothing writes to it: an open without the check would block here.
  EXPECT_EQ(error_of(path("pipe"), kMaxInputFileBytes),
            path("pipe") + ": is not a regular file (FIFO)");
  EXPECT_EQ(error_of("/dev/zero", kMaxInputFileBytes),
            "/dev/zero: is not a regular file (character device)");
  EXPECT_EQ(error_of(path("none"), kMaxInputFileBytes),
            path("none") + ": cannot open file: No such file or directory");
  EXPECT_EQ(input_file_problem(path("none")), kFileMissing);
}

TEST_F(InputFileTest, FileOverTheLimitIsRefusedBeforeReading) {
  std::ofstream(path("big.txt"), std::ios::binary) << std::string(3u << 20, 'y');
  EXPECT_EQ(error_of(path("big.txt"), std::uintmax_t{2} << 20),
            path("big.txt") + ": is 3 MiB, more than the 2 MiB limit");
  EXPECT_EQ(error_of(path("big.txt"), 1000),
            path("big.txt") + ": is 3 MiB, more than the 1000 bytes limit");
  EXPECT_EQ(read_input_file(path("big.txt"), std::uintmax_t{3} << 20).size(), 3u << 20);
}

TEST_F(InputFileTest, YamlLoaderUsesTheChecks) {
  try {
    (void)YamlNode::load_file(dir_.string());
    ADD_FAILURE() << "a directory loaded";
  } catch (const InputError& e) {
    // Not "file is empty", which is what reading a directory used to say.
    EXPECT_EQ(std::string(e.what()), dir_.string() + ": is a directory");
  }
}

}  // namespace
}  // namespace animrt
