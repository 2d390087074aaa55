// Input files: only regular files under the size limit are read.

#include "animrt/core/input_file.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/core/yaml_doc.hpp"
#include "support/hostile_files.hpp"

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

// An output saved by renaming a new file over its path may replace a
// regular file, a link or nothing; never a FIFO, a device or a folder.
TEST_F(InputFileTest, OnlyARegularFileALinkOrNothingMayBeReplacedByAnOutput) {
  const auto refusal = [](const std::string& file) -> std::string {
    try {
      check_replaceable_file(file);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  std::ofstream(path("old.csv")) << "x\n";
  ASSERT_EQ(::mkfifo(path("pipe").c_str(), 0600), 0);
  fs::create_symlink(path("pipe"), path("link"));
  EXPECT_EQ(refusal(path("old.csv")), "");
  EXPECT_EQ(refusal(path("none.csv")), "");
  EXPECT_EQ(refusal(path("link")), "");
  EXPECT_EQ(refusal(path("pipe")), path("pipe") + ": is not a regular file (FIFO)");
  EXPECT_EQ(refusal("/dev/null"), "/dev/null: is not a regular file (character device)");
  EXPECT_EQ(refusal(dir_.string()), dir_.string() + ": is a directory");
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

std::string yaml_error_of(const std::string& text) {
  try {
    (void)YamlNode::load_string(text, "t.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST_F(InputFileTest, YamlFileOverItsOwnLimitIsRefusedBeforeReading) {
  // A single 5 MB value: yaml-cpp would hold it several times over.
  const std::string text = "name: " + std::string(5000000, 'x') + "\n";
  std::ofstream(path("long.yaml"), std::ios::binary) << text;
  try {
    (void)YamlNode::load_file(path("long.yaml"));
    ADD_FAILURE() << "a 5 MB YAML file loaded";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path("long.yaml") + ": is 5000007 bytes, more than the 4 MiB limit");
  }
  EXPECT_EQ(yaml_error_of(text), "t.yaml: is 5000007 bytes, more than the 4 MiB limit");
}

TEST_F(InputFileTest, YamlNodesPastTheLimitAreRefusedWhereTheyPassIt) {
  // Two bytes a node: 200 KB that yaml-cpp would turn into some 50 MiB per
  // 100000 nodes. The root map, its key and the list come first.
  std::string items;
  for (std::size_t i = 0; i < kMaxYamlNodes; ++i) items += "- 0\n";
  EXPECT_EQ(yaml_error_of("a:\n" + items),
            "t.yaml:99999:3: more than 100000 YAML nodes (values, lists and maps); a "
            "configuration needs far fewer");
  // One node fewer loads.
  items.resize(items.size() - 4 * 3);
  EXPECT_EQ(yaml_error_of("a:\n" + items), "no error");
}

std::string bytes_error_of(const std::string& file, std::uintmax_t max_bytes,
                           std::uintmax_t max_inflated) {
  try {
    (void)read_input_bytes(file, max_bytes, max_inflated);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST_F(InputFileTest, BytesArePlainOrInflatedMemberAfterMember) {
  std::ofstream(path("plain.bin"), std::ios::binary) << "abc";
  const std::vector<std::uint8_t> plain = read_input_bytes(path("plain.bin"));
  EXPECT_EQ(std::string(plain.begin(), plain.end()), "abc");
  // Two gzip members in a row read as one stream, as gzip -d reads them.
  test::write_gzip_bomb(path("one.gz"), 0, "first ");
  test::write_gzip_bomb(path("two.gz"), 3, "second");
  {
    std::ofstream both(path("both.gz"), std::ios::binary);
    both << std::ifstream(path("one.gz"), std::ios::binary).rdbuf()
         << std::ifstream(path("two.gz"), std::ios::binary).rdbuf();
  }
  const std::vector<std::uint8_t> both = read_input_bytes(path("both.gz"));
  EXPECT_EQ(std::string(both.begin(), both.end()), std::string("first second\0\0\0", 15));
}

TEST_F(InputFileTest, BytesRefuseFifoDeviceAndGzipBombNamingTheFile) {
  const test::UnblockedFifo fifo(path("pipe.gz"));
  EXPECT_EQ(bytes_error_of(fifo.path(), kMaxInputFileBytes, kMaxInflatedBytes),
            fifo.path() + ": is not a regular file (FIFO)");
  EXPECT_EQ(bytes_error_of("/dev/zero", kMaxInputFileBytes, kMaxInflatedBytes),
            "/dev/zero: is not a regular file (character device)");
  // 80 MiB of zeros in some 80 KB: refused at the 64 MiB limit while
  // inflating, and a lower limit stops it sooner.
  test::write_gzip_bomb(path("bomb.gz"), std::uint64_t{80} << 20);
  EXPECT_LT(fs::file_size(path("bomb.gz")), 200000u);
  EXPECT_EQ(bytes_error_of(path("bomb.gz"), kMaxInputFileBytes, kMaxInflatedBytes),
            path("bomb.gz") + ": gzip data inflates to more than the 64 MiB limit");
  EXPECT_EQ(bytes_error_of(path("bomb.gz"), kMaxInputFileBytes, std::uintmax_t{1} << 20),
            path("bomb.gz") + ": gzip data inflates to more than the 1 MiB limit");
  // A cut stream is named too.
  fs::copy_file(path("bomb.gz"), path("cut.gz"));
  fs::resize_file(path("cut.gz"), fs::file_size(path("bomb.gz")) / 2);
  EXPECT_EQ(bytes_error_of(path("cut.gz"), kMaxInputFileBytes, std::uintmax_t{128} << 20),
            path("cut.gz") + ": gzip data is truncated");
}

TEST(HeaderCount, CountsMustFitTheFileBeforeAnythingIsSized) {
  EXPECT_NO_THROW(check_header_count("m.bin", "header", "the frames", 10, 8, 80));
  try {
    check_header_count("m.bin", "header", "the frames", std::uint64_t{1} << 40, 8, 80);
    ADD_FAILURE() << "a count past the file's size passed";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "m.bin: header: the frames (1099511627776 x 8 bytes) is larger than the file "
                 "(80 bytes)");
  }
}

// Output paths are judged before a command's work: a folder where a file
// goes, no folder to hold it, a file where a folder goes.
TEST_F(InputFileTest, OutputPathsThatCannotBeWrittenAreNamedBeforeTheWork) {
  const std::string file = path("f.txt");
  std::ofstream(file) << "x";
  EXPECT_EQ(output_file_problem(path("new.csv")), "");
  EXPECT_EQ(output_file_problem(file), "");  // replaced
  EXPECT_EQ(output_file_problem(dir_.string()), "is a folder, expected a file to write");
  EXPECT_EQ(output_file_problem(path("no/x.csv")),
            "its folder \"" + path("no") + "\" does not exist");
  EXPECT_EQ(output_file_problem(file + "/x.csv"), "\"" + file + "\" is a file, not a folder");
  EXPECT_EQ(output_folder_problem(path("no/x/y")), "");  // made with its parents
  EXPECT_EQ(output_file_problem("x.csv"), "");           // the working folder
  EXPECT_EQ(output_folder_problem(path("out/a")), "");
  EXPECT_EQ(output_folder_problem(dir_.string()), "");
  EXPECT_EQ(output_folder_problem(file), "is a file, expected a folder");
  EXPECT_EQ(output_folder_problem(file + "/a"), "\"" + file + "\" is a file, not a folder");
  // Links are judged by what they point to: a dangling one into a missing
  // folder (absolute or relative to the link), one that loops.
  std::filesystem::create_symlink(path("no/x.csv"), path("dangling"));
  EXPECT_EQ(output_file_problem(path("dangling")), "is a link to \"" + path("no/x.csv") +
                                                       "\": its folder \"" + path("no") +
                                                       "\" does not exist");
  std::filesystem::create_symlink("no/y.csv", path("relative"));
  EXPECT_EQ(output_file_problem(path("relative")), "is a link to \"" + path("no/y.csv") +
                                                       "\": its folder \"" + path("no") +
                                                       "\" does not exist");
  std::filesystem::create_symlink("new_target.csv", path("to_new"));
  EXPECT_EQ(output_file_problem(path("to_new")), "");  // the link makes a new file
  std::filesystem::create_symlink(path("loop_b"), path("loop_a"));
  std::filesystem::create_symlink(path("loop_a"), path("loop_b"));
  EXPECT_EQ(output_file_problem(path("loop_a")).rfind("is a link that cannot be followed: ", 0), 0u)
      << output_file_problem(path("loop_a"));
}

// Every byte is written, or the failing write's errno is returned with the
// count that made it.
TEST_F(InputFileTest, WriteAllWritesEverythingOrSaysWhyNot) {
  const std::string file = path("w.bin");
  const std::string text(200000, 'a');
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  std::size_t written = 0;
  EXPECT_EQ(write_all(fd, text.data(), text.size(), &written), 0);
  EXPECT_EQ(written, text.size());
  ::close(fd);
  EXPECT_EQ(fs::file_size(file), text.size());
  const int full = ::open("/dev/full", O_WRONLY);
  ASSERT_GE(full, 0);
  EXPECT_EQ(write_all(full, text.data(), text.size(), &written), ENOSPC);
  EXPECT_EQ(written, 0u);
  ::close(full);
  EXPECT_EQ(write_all(-1, text.data(), 1), EBADF);
}

}  // namespace
}  // namespace animrt
