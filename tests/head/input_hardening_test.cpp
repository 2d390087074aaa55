// Hostile or damaged head inputs: model files and WAV headers.

#include <gtest/gtest.h>
#include <sndfile.h>
#include <sys/stat.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/head/model.hpp"
#include "animrt/core/error.hpp"
#include "head_test_util.hpp"

namespace animrt::head {
namespace {

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

template <typename F>
std::string error_of(F&& load) {
  try {
    load();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ModelFileHardening, NulByteInsideANumberNamesFileAndLine) {
  const std::string dir = test::temp_dir("nulmodel");
  std::string text = read_all(std::string(ANIMRT_SOURCE_DIR) + "/configs/head/model.txt");
  // "window_s 0.025..." on line 2 becomes "window_s 0.0<NUL>25...": strtod
  // would read 0.0 and stop.
  const auto line2 = text.find('\n') + 1;
  const auto at = text.find("window_s 0.0", line2) + std::strlen("window_s 0.0");
  text[at] = '\0';
  const std::string path = dir + "/nul.txt";
  std::ofstream(path, std::ios::binary) << text;
  EXPECT_EQ(error_of([&] { load_model(path); }),
            path + ":2:" + std::to_string(at - line2 + 1) +
                ": features: NUL byte in the line (a corrupted or binary file?)");
  std::filesystem::remove_all(dir);
}

class WavHardening : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::temp_dir("wavhard"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string dir_;
};

TEST_F(WavHardening, HeaderClaimingOneHertzIsRejectedBeforeAnyAllocation) {
  const std::string path = dir_ + "/one_hz.wav";
  write_wav(path, test::tone(150, 0.5));
  // Canonical 44-byte header: sample rate at 24, byte rate at 28.
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  const unsigned char one[4] = {1, 0, 0, 0};
  const unsigned char two[4] = {2, 0, 0, 0};
  f.seekp(24);
  f.write(reinterpret_cast<const char*>(one), 4);
  f.write(reinterpret_cast<const char*>(two), 4);
  f.close();
  EXPECT_EQ(error_of([&] { load_audio(path, 24000); }),
            path + ": sample rate 1 Hz in the header, expected 4000..384000 Hz");
}

TEST_F(WavHardening, NanAndInfiniteSamplesAreRejectedWithTheFileNamed) {
  for (float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    const std::string path = dir_ + "/float.wav";
    SF_INFO info{};
    info.samplerate = 16000;
    info.channels = 1;
    info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
    SNDFILE* sf = sf_open(path.c_str(), SFM_WRITE, &info);
    ASSERT_NE(sf, nullptr);
    std::vector<float> samples(1600, 0.1f);
    samples[400] = bad;
    sf_writef_float(sf, samples.data(), static_cast<sf_count_t>(samples.size()));
    sf_close(sf);
    EXPECT_EQ(error_of([&] { load_audio(path); }),
              path + ": sample 400 (at 0.025 s) is not a finite number (NaN or infinity)");
  }
}

TEST_F(WavHardening, TruncatedDirectoryAndFifoHaveClearMessages) {
  write_wav(dir_ + "/good.wav", test::tone(150, 0.5));  // 8000 samples of 16 bits
  std::filesystem::copy_file(dir_ + "/good.wav", dir_ + "/cut.wav");
  std::filesystem::resize_file(dir_ + "/cut.wav", 44 + 1000);
  EXPECT_EQ(error_of([&] { load_audio(dir_ + "/cut.wav"); }),
            dir_ +
                "/cut.wav: truncated WAV file: the data chunk declares 16000 bytes but only "
                "1000 are present");
  std::filesystem::create_directories(dir_ + "/folder.wav");
  EXPECT_EQ(error_of([&] { load_audio(dir_ + "/folder.wav"); }),
            dir_ + "/folder.wav: is a directory");
  ASSERT_EQ(::mkfifo((dir_ + "/pipe.wav").c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { load_audio(dir_ + "/pipe.wav"); }),
            dir_ + "/pipe.wav: is not a regular file (FIFO)");
}

}  // namespace
}  // namespace animrt::head
