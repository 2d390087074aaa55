// End to end: the CLI (corpus, train, synth, eval, features), the head
// motion source on the bundled model and utterance, and the pitch tracker's
// gross pitch error against Praat.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/controllers/head/head_source.hpp"
#include "animrt/controllers/head/pose_io.hpp"
#include "animrt/controllers/head/prosody.hpp"
#include "support/alloc_counter.hpp"
#include "support/wav_file.hpp"

namespace animrt::head {
namespace {

const std::string kBin = std::string(ANIMRT_BINARY_DIR) + "/bin/animrt";
const std::string kSrc = ANIMRT_SOURCE_DIR;

std::string tmp(const std::string& tag) {
  const auto d = std::filesystem::temp_directory_path() /
                 ("animrt_head_it_" + tag + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d.string();
}

int run(const std::string& cmd) {
  const int rc = std::system((cmd + " > /dev/null 2>&1").c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(HeadCli, CorpusTrainSynthEvalFeatures) {
  const std::string d = tmp("cli");
  ASSERT_EQ(run(kBin + " head corpus --out " + d + "/corpus --utterances 5 --speakers 1 --quiet"),
            0);
  ASSERT_EQ(run(kBin + " head train " + d + "/corpus --out " + d +
                "/m.txt -K 4 -S 2 -M 1 --iterations 2 --quiet"),
            0);
  ASSERT_EQ(run(kBin + " head synth " + d + "/m.txt " + kSrc +
                "/configs/head/utterance.wav --out " + d + "/p.csv"),
            0);
  const PoseTrack p = load_euler_csv(d + "/p.csv");
  EXPECT_GT(p.size(), 120u);
  EXPECT_EQ(run(kBin + " head eval " + d + "/m.txt " + d + "/corpus"), 0);
  ASSERT_EQ(
      run(kBin + " head features " + kSrc + "/configs/head/utterance.wav --out " + d + "/f.csv"),
      0);
  std::ifstream f(d + "/f.csv");
  std::string header;
  std::getline(f, header);
  EXPECT_EQ(header,
            "time_s,f0_hz,energy,voiced,f0_filled_hz,f0_st,energy_db,d_f0_st,d_energy_db,dd_f0_st,"
            "dd_energy_db");
  // Bad input: exit code 2.
  std::ofstream(d + "/bad.txt") << "animrt-head-model 7\n";
  EXPECT_EQ(run(kBin + " head synth " + d + "/bad.txt " + kSrc +
                "/configs/head/utterance.wav --out " + d + "/x.csv"),
            2);
  EXPECT_EQ(run(kBin + " head features " + d + "/bad.txt --out " + d + "/x.csv"), 2);
  std::filesystem::remove_all(d);
}

// A sound shorter than one analysis window (25 ms) gives no pose: synth and
// features say so (exit 2) and write nothing, rather than an empty file
// with exit 0. One window's worth is enough for a frame.
TEST(HeadCli, ASoundShorterThanOneWindowIsRefused) {
  const std::string d = tmp("short");
  for (const std::size_t samples : {std::size_t{1}, std::size_t{480}}) {  // 24 kHz: 20 ms
    ASSERT_TRUE(write_float_wav(d + "/short.wav", std::vector<float>(samples, 0.1f), 24000));
    for (const std::string& command :
         {" head synth " + kSrc + "/configs/head/model.txt " + d + "/short.wav --out " + d +
              "/p.csv",
          " head features " + d + "/short.wav --out " + d + "/p.csv"}) {
      EXPECT_EQ(std::system((kBin + command + " > " + d + "/said.txt 2>&1").c_str()), 2 << 8)
          << command << " with " << samples << " samples";
      std::ifstream said_file(d + "/said.txt");
      const std::string said((std::istreambuf_iterator<char>(said_file)),
                             std::istreambuf_iterator<char>());
      EXPECT_NE(said.find(d + "/short.wav: the sound is shorter than one analysis window (25 ms)"),
                std::string::npos)
          << said;
      EXPECT_FALSE(std::filesystem::exists(d + "/p.csv")) << command;
    }
  }
  ASSERT_TRUE(write_float_wav(d + "/short.wav", std::vector<float>(600, 0.1f), 24000));
  EXPECT_EQ(run(kBin + " head synth " + kSrc + "/configs/head/model.txt " + d +
                "/short.wav --out " + d + "/p.csv"),
            0);
  EXPECT_GE(load_euler_csv(d + "/p.csv").size(), 1u);
  std::filesystem::remove_all(d);
}

TEST(HeadSource, BundledModelMovesNeckAndJawWithinLimits) {
  HeadMotionConfig c;
  c.model = kSrc + "/configs/head/model.txt";
  c.audio = kSrc + "/configs/head/utterance.wav";
  c.precomputed = true;  // the same streaming pipeline, run at load (lockstep-friendly)
  c.yaw.joint = "yaw";
  c.pitch.joint = "pitch";
  c.pitch.sign = -1;
  c.roll.joint = "roll";
  c.jaw.joint = "jaw";
  std::vector<JointSpec> joints(4);
  const char* names[] = {"yaw", "pitch", "roll", "jaw"};
  for (int i = 0; i < 4; ++i) {
    joints[static_cast<std::size_t>(i)].name = names[i];
    joints[static_cast<std::size_t>(i)].limits = {deg_to_rad(-15), deg_to_rad(15), 1, 1};
  }
  joints[3].limits = {0, deg_to_rad(20), 1, 1};
  auto src = make_head_source(c, joints);
  EXPECT_EQ(src->driven_joints().size(), 4u);
  std::vector<double> t(4, 0.0), lo(4, 1e9), hi(4, -1e9);
  const auto before = test::thread_allocations();
  for (int i = 0; i < 800; ++i) {
    src->sample(i * 0.01, t);
    for (int k = 0; k < 4; ++k) {
      lo[static_cast<std::size_t>(k)] =
          std::min(lo[static_cast<std::size_t>(k)], t[static_cast<std::size_t>(k)]);
      hi[static_cast<std::size_t>(k)] =
          std::max(hi[static_cast<std::size_t>(k)], t[static_cast<std::size_t>(k)]);
    }
  }
  EXPECT_EQ(test::thread_allocations(), before);  // sample() never allocates
  for (int k = 0; k < 4; ++k) {
    EXPECT_GE(lo[static_cast<std::size_t>(k)],
              joints[static_cast<std::size_t>(k)].limits.min_position - 1e-12);
    EXPECT_LE(hi[static_cast<std::size_t>(k)],
              joints[static_cast<std::size_t>(k)].limits.max_position + 1e-12);
    EXPECT_GT(hi[static_cast<std::size_t>(k)] - lo[static_cast<std::size_t>(k)], deg_to_rad(1.0))
        << names[k];
  }
  // A joint the robot does not have.
  c.roll.joint = "tail";
  EXPECT_THROW(make_head_source(c, joints), InputError);
}

// Gross pitch error of our YIN features against Praat's autocorrelation
// tracker on espeak-ng speech: frames voiced in both, |error| > 20 %.
TEST(PitchTracker, GrossPitchErrorAgainstPraat) {
  ASSERT_EQ(std::system("command -v praat > /dev/null 2>&1"), 0)
      << "praat not found (scripts/install-deps.sh installs it)";
  const std::string d = tmp("gpe");
  const std::string wav = kSrc + "/configs/head/utterance.wav";
  std::ofstream(d + "/pitch.praat") << "form args\n  sentence wav\n  sentence out\nendform\n"
                                       "s = Read from file: wav$\np = To Pitch: 0.005, 75, 500\n"
                                       "n = Get number of frames\nwriteFileLine: out$, \"t f\"\n"
                                       "for i to n\n  t = Get time from frame number: i\n"
                                       "  f = Get value in frame: i, \"Hertz\"\n"
                                       "  appendFileLine: out$, fixed$(t, 5), \" \", f\nendfor\n";
  ASSERT_EQ(run("praat --run " + d + "/pitch.praat " + wav + " " + d + "/ref.txt"), 0);
  std::ifstream in(d + "/ref.txt");
  std::string line;
  std::getline(in, line);
  std::vector<std::pair<double, double>> ref;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string t, f;
    ls >> t >> f;
    ref.push_back({std::stod(t), f.find("undefined") == std::string::npos ? std::stod(f) : 0.0});
  }
  ASSERT_GT(ref.size(), 100u);
  const FeatureTrack ours = extract_features_file(wav, FeatureConfig{});
  int both = 0, gross = 0;
  for (std::size_t i = 0; i < ours.size(); ++i) {
    const double t = ours.time(i);
    auto it = std::lower_bound(ref.begin(), ref.end(), std::make_pair(t, -1.0));
    if (it == ref.end()) break;
    if (!ours.raw[i].voiced || it->second <= 0) continue;
    ++both;
    gross += std::abs(ours.raw[i].f0_hz - it->second) > 0.2 * it->second;
  }
  ASSERT_GT(both, 50);
  const double gpe = static_cast<double>(gross) / both;
  std::cout << "gross pitch error vs Praat: " << 100 * gpe << " % of " << both
            << " frames voiced in both\n";
  EXPECT_LT(gpe, 0.10);
  std::filesystem::remove_all(d);
}

}  // namespace
}  // namespace animrt::head
