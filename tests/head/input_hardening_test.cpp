// Hostile or damaged head inputs: model files and WAV headers.

#include <gtest/gtest.h>
#include <sndfile.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/head/model.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/head/corpus.hpp"
#include "head_test_util.hpp"
#include "support/hostile_files.hpp"
#include "support/wav_file.hpp"

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

// Values a model file cannot mean, each refused at its line: a smoothing
// noise of 1e300 degrees (the poses came out near 1e308), a covariance
// that is not positive definite, a log-probability above 0, and a line
// after "end".
TEST(ModelFileHardening, ValuesNoTrainedModelHasAreRefusedAtTheirLine) {
  const std::string dir = test::temp_dir("badmodel");
  const std::string shipped = read_all(std::string(ANIMRT_SOURCE_DIR) + "/configs/head/model.txt");
  const auto line_of = [&](const std::string& start) {
    const auto at = shipped.find("\n" + start);
    return 2 + std::count(shipped.begin(), shipped.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  };
  struct Case {
    std::string from, to, start, message;
  };
  const std::vector<Case> cases = {
      {"noise_deg 0.5", "noise_deg 1e300", "smoothing",
       "smoothing: noise_deg must be from 0 to 10"},
      {"cov 1.3899222431725102", "cov -1000", "cluster 0",
       "cluster: cov must be a symmetric positive-definite matrix"},
      {"a -0.069775388071348823", "a 5", "a -0.069775388071348823",
       "a: log-probabilities must be at most 0"},
  };
  const std::string path = dir + "/model.txt";
  for (const Case& c : cases) {
    std::string text = shipped;
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    std::ofstream(path, std::ios::binary) << text;
    EXPECT_EQ(error_of([&] { load_model(path); }),
              path + ":" + std::to_string(line_of(c.start)) + ": " + c.message);
  }
  std::ofstream(path, std::ios::binary) << shipped << "next 0 0\n";
  const long lines = std::count(shipped.begin(), shipped.end(), '\n');
  EXPECT_EQ(error_of([&] { load_model(path); }),
            path + ":" + std::to_string(lines + 1) +
                ": end: unexpected line after \"end\": \"next 0 0\"");
  std::ofstream(path, std::ios::binary) << shipped << "\n# a note\n";
  EXPECT_EQ(error_of([&] { load_model(path); }), "no error");
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
    std::vector<float> samples(1600, 0.1f);
    samples[400] = bad;
    ASSERT_TRUE(write_float_wav(path, samples, 16000));
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

// A FLAC file whose STREAMINFO claims 2^28 frames: nothing may be sized from
// that claim (a buffer of 1 GiB for 32 KB of sound).
TEST_F(WavHardening, FlacHeaderClaimingFarMoreFramesThanItCanHoldIsRefused) {
  const std::string path = dir_ + "/lying.flac";
  {
    SF_INFO info{};
    info.samplerate = 16000;
    info.channels = 1;
    info.format = SF_FORMAT_FLAC | SF_FORMAT_PCM_16;
    SNDFILE* sf = sf_open(path.c_str(), SFM_WRITE, &info);
    ASSERT_NE(sf, nullptr);
    const Audio a = test::tone(150, 1.0);
    sf_writef_float(sf, a.samples.data(), static_cast<sf_count_t>(a.samples.size()));
    sf_close(sf);
  }
  // "fLaC", a 4-byte block header, then STREAMINFO: its 36-bit total sample
  // count is the low nibble of file byte 21 and bytes 22..25, big-endian.
  std::string bytes = read_all(path);
  ASSERT_EQ(bytes.substr(0, 4), "fLaC");
  bytes[21] = static_cast<char>(bytes[21] & 0xf0);
  const unsigned char total[4] = {0x10, 0, 0, 0};  // 2^28
  std::memcpy(bytes.data() + 22, total, 4);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  const std::string e = error_of([&] { load_audio(path); });
  EXPECT_EQ(e.rfind(path + ": the header declares 268435456 frames x 1 channels, more than 4096 "
                           "samples per byte of its ",
                    0),
            0u)
      << e;

  // A claim within that bound but beyond what the file holds is read in
  // chunks and refused as truncated.
  bytes[22] = 0;
  const unsigned char smaller[4] = {0, 0x01, 0, 0};  // 65536 frames, 16000 present
  std::memcpy(bytes.data() + 22, smaller, 4);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_EQ(error_of([&] { load_audio(path); }),
            path + ": truncated audio file: expected 65536 frames, read 16000");
}

TEST_F(WavHardening, CorpusFolderRefusesARecordingOrPoseFileThatIsAFifo) {
  write_wav(dir_ + "/a.wav", test::tone(150, 0.2));
  std::ofstream(dir_ + "/a.csv") << "time_s,yaw_deg,pitch_deg,roll_deg\n0,0,0,0\n";
  {
    const animrt::test::UnblockedFifo fifo(dir_ + "/b.wav");
    EXPECT_EQ(error_of([&] { (void)list_corpus(dir_); }),
              fifo.path() + ": is not a regular file (FIFO)");
  }
  write_wav(dir_ + "/b.wav", test::tone(150, 0.2));
  const animrt::test::UnblockedFifo pose(dir_ + "/b.csv");
  EXPECT_EQ(error_of([&] { (void)list_corpus(dir_); }),
            pose.path() + ": is not a regular file (FIFO)");
}

}  // namespace
}  // namespace animrt::head
