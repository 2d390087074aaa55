// On the tiny generated corpus: loaders, training, the mean-pose baseline,
// model files (round trip and corrupt files), streaming vs offline.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "animrt/controllers/head/model.hpp"
#include "animrt/controllers/head/streaming.hpp"
#include "animrt/controllers/head/synthesis.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/head/corpus.hpp"
#include "animrt/learn/head/evaluation.hpp"
#include "animrt/learn/head/trainer.hpp"
#include "head_test_util.hpp"

namespace animrt::head {
namespace {

struct Trained {
  std::vector<PreparedUtterance> train, test;
  HeadModel model;
};

TrainOptions small_options() {
  TrainOptions o;
  o.clusters = 8;
  o.states = 3;
  o.mixtures = 1;
  o.iterations = 4;
  return o;
}

const Trained& trained() {
  static const Trained t = [] {
    Trained out;
    const auto split = split_corpus(list_corpus(test::tiny_corpus()), 0.7, 1);
    const FeatureConfig fc;
    out.train = prepare_corpus(split.train, fc);
    out.test = prepare_corpus(split.test, fc);
    out.model = train_model(out.train, fc, small_options());
    return out;
  }();
  return t;
}

TEST(Corpus, ListsUtterancesAndSplitsReproducibly) {
  const auto utts = list_corpus(test::tiny_corpus());
  ASSERT_EQ(utts.size(), 10u);
  EXPECT_EQ(utts[0].name, "utt_000");
  const auto a = split_corpus(utts, 0.8, 3), b = split_corpus(utts, 0.8, 3);
  EXPECT_EQ(a.train.size(), 8u);
  EXPECT_EQ(a.test.size(), 2u);
  for (std::size_t i = 0; i < a.test.size(); ++i) EXPECT_EQ(a.test[i].name, b.test[i].name);
}

TEST(Corpus, MissingPoseFileIsAnError) {
  const std::string dir = test::temp_dir("nopose");
  write_wav(dir + "/a.wav", test::tone(150, 0.2));
  try {
    list_corpus(dir);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no head-pose file"), std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

TEST(Training, OneSpeakerBeatsTheMeanPoseBaseline) {
  const Trained& t = trained();
  EXPECT_EQ(t.model.clusters(), 8);
  EXPECT_EQ(t.model.hmms.size(), 8u);
  const Evaluation train_eval = evaluate(t.model, t.train, mean_pose(t.train));
  const Evaluation test_eval = evaluate(t.model, t.test, mean_pose(t.train));
  // Held-out utterances are the claim; on the training ones the synthesized
  // motion must at least follow the original closely.
  EXPECT_LT(test_eval.distance_deg.mean, test_eval.baseline_distance_deg.mean);
  EXPECT_GT(train_eval.cca.mean, 0.6);
  EXPECT_GT(test_eval.cca.mean, 0.3);
}

TEST(Synthesis, PosesAtTheOutputRateWithinTheCodebook) {
  const Trained& t = trained();
  const PoseTrack p = synthesize(t.model, t.test[0].track);
  const double duration = t.test[0].track.time(t.test[0].track.size() - 1);
  EXPECT_NEAR(static_cast<double>(p.size()), std::floor(duration * 120) + 1, 1.0);
  const Eigen::Vector3d lo = t.model.codebook.means.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = t.model.codebook.means.colwise().maxCoeff().transpose();
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(p.times[i], static_cast<double>(i) / 120.0, 1e-12);
    EXPECT_GE(p.poses[i].pitch, lo(1) - 2.0);
    EXPECT_LE(p.poses[i].pitch, hi(1) + 2.0);
    if (i > 0) {
      EXPECT_LT(std::abs(p.poses[i].yaw - p.poses[i - 1].yaw), 2.0);  // smooth + noise
    }
  }
  // Same seed, same output.
  const PoseTrack again = synthesize(t.model, t.test[0].track);
  EXPECT_EQ(again.poses[50].yaw, p.poses[50].yaw);
}

TEST(Streaming, FollowsOfflineSynthesisWithBoundedLag) {
  const Trained& t = trained();
  const auto utts = list_corpus(test::tiny_corpus());
  const Audio audio = load_audio(utts[0].audio_path);
  const PoseTrack offline = synthesize(t.model, audio);
  StreamOptions so;
  so.input_rate = audio.sample_rate;
  StreamingSynthesizer s(t.model, so);
  std::vector<StreamPose> out;
  double worst = 0;
  const std::size_t block = static_cast<std::size_t>(audio.sample_rate / 100);
  for (std::size_t i = 0; i < audio.samples.size(); i += block) {
    const std::size_t n = std::min(block, audio.samples.size() - i);
    const std::size_t before = out.size();
    s.push(std::span<const float>(audio.samples.data() + i, n), out);
    for (std::size_t j = before; j < out.size(); ++j)
      worst = std::max(worst, s.audio_time_s() - out[j].t);
  }
  s.finish(out);
  EXPECT_LE(worst, s.worst_case_latency_s() + 0.011);
  ASSERT_NEAR(static_cast<double>(out.size()), static_cast<double>(offline.size()), 2.0);
  // Against the original motion, streaming does about as well as offline
  // (it commits decisions with a fixed lag, so the paths differ in places).
  const PoseTrack original = load_pose_file(utts[0].pose_path);
  double d_stream = 0, d_offline = 0;
  const std::size_t n = std::min(out.size(), offline.size());
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(out[i].t, offline.times[i], 1e-9);
    const Euler o = original.at(out[i].t);
    d_stream +=
        std::hypot(out[i].pose.yaw - o.yaw, out[i].pose.pitch - o.pitch, out[i].pose.roll - o.roll);
    const Euler& f = offline.poses[i];
    d_offline += std::hypot(f.yaw - o.yaw, f.pitch - o.pitch, f.roll - o.roll);
  }
  EXPECT_LT(d_stream, 1.5 * d_offline + 1.0 * static_cast<double>(n))
      << d_stream / n << " vs " << d_offline / n;
}

// Live speech: causal smoothing, a short decoder lag and no gap fill put
// every head pose on the output within 150 ms of audio (counted in samples
// pushed), and the head still moves about as offline synthesis does.
TEST(Streaming, CausalSmoothingFollowsLiveSpeechWithin150ms) {
  const Trained& t = trained();
  const auto utts = list_corpus(test::tiny_corpus());
  const Audio audio = load_audio(utts[0].audio_path);
  const PoseTrack offline = synthesize(t.model, audio);
  StreamOptions so;
  so.input_rate = audio.sample_rate;
  so.causal = true;
  so.decoder_lag_s = 0.07;
  so.max_gap_s = 0.0;
  StreamingSynthesizer s(t.model, so);
  std::vector<StreamPose> out;
  double worst = 0;
  const std::size_t block = static_cast<std::size_t>(audio.sample_rate / 100);
  for (std::size_t i = 0; i < audio.samples.size(); i += block) {
    const std::size_t before = out.size();
    s.push(
        std::span<const float>(audio.samples.data() + i, std::min(block, audio.samples.size() - i)),
        out);
    for (std::size_t j = before; j < out.size(); ++j)
      worst = std::max(worst, s.audio_time_s() - out[j].t);
  }
  s.finish(out);
  EXPECT_LE(worst, 0.15);
  EXPECT_LE(worst, s.worst_case_latency_s() + 0.011);
  EXPECT_LE(s.worst_case_latency_s() + 0.01, 0.15);
  ASSERT_NEAR(static_cast<double>(out.size()), static_cast<double>(offline.size()), 2.0);
  const PoseTrack original = load_pose_file(utts[0].pose_path);
  double d_stream = 0, d_offline = 0, spread = 0;
  const std::size_t n = std::min(out.size(), offline.size());
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(out[i].t, offline.times[i], 1e-9);
    const Euler o = original.at(out[i].t);
    d_stream +=
        std::hypot(out[i].pose.yaw - o.yaw, out[i].pose.pitch - o.pitch, out[i].pose.roll - o.roll);
    const Euler& f = offline.poses[i];
    d_offline += std::hypot(f.yaw - o.yaw, f.pitch - o.pitch, f.roll - o.roll);
    spread = std::max(spread, std::abs(out[i].pose.pitch - out[0].pose.pitch));
  }
  EXPECT_LT(d_stream, 1.5 * d_offline + 1.0 * static_cast<double>(n))
      << d_stream / n << " vs " << d_offline / n;
  EXPECT_GT(spread, 1.0);  // the head moves, not only its +-0.5 deg noise
}

// ------------------------------------------------------------ model files

TEST(ModelFile, RoundTripDecodesTheSame) {
  const Trained& t = trained();
  const std::string dir = test::temp_dir("model");
  save_model(dir + "/m.txt", t.model);
  const HeadModel back = load_model(dir + "/m.txt");
  EXPECT_EQ(back.clusters(), t.model.clusters());
  EXPECT_EQ(back.training_utterances, t.model.training_utterances);
  EXPECT_EQ(decode_track(back, t.test[0].track), decode_track(t.model, t.test[0].track));
  for (int k = 0; k < t.model.clusters(); ++k)
    EXPECT_LT((back.cluster_pose(k) - t.model.cluster_pose(k)).norm(), 1e-9) << "cluster " << k;
  std::filesystem::remove_all(dir);
}

std::string load_error(const std::string& path) {
  try {
    load_model(path);
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    return e.what();
  }
  ADD_FAILURE() << "loaded " << path;
  return "";
}

TEST(ModelFile, CorruptMismatchedAndMissingFilesAreClearErrors) {
  const Trained& t = trained();
  const std::string dir = test::temp_dir("badmodel");
  const std::string good = dir + "/good.txt";
  save_model(good, t.model);
  std::stringstream buf;
  buf << std::ifstream(good).rdbuf();
  const std::string text = buf.str();
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(dir + "/" + name) << content;
    return dir + "/" + name;
  };
  EXPECT_NE(load_error(dir + "/none.txt").find("not found"), std::string::npos);
  EXPECT_NE(load_error(write("magic.txt", "hello\n")).find("not an animrt head model"),
            std::string::npos);
  const std::string magic = "animrt-head-model " + std::to_string(kModelFormatVersion);
  const std::string other = std::to_string(kModelFormatVersion + 1);
  std::string v2 = text;
  v2.replace(v2.find(magic), magic.size(), "animrt-head-model " + other);
  EXPECT_NE(load_error(write("v2.txt", v2)).find("version " + other + " is not supported"),
            std::string::npos);
  // Cut after a whole line, half way through: the file ends early.
  const std::string cut = text.substr(0, text.rfind('\n', text.size() / 2) + 1);
  const std::string cut_msg = load_error(write("cut.txt", cut));
  EXPECT_NE(cut_msg.find("truncated"), std::string::npos) << cut_msg;
  std::string bad = text;
  const auto pos = bad.find("mix ");
  bad.replace(pos, 8, "mix oops");
  const std::string msg = load_error(write("bad.txt", bad));
  EXPECT_NE(msg.find("expected a number"), std::string::npos) << msg;
  EXPECT_NE(msg.find(": mix: "), std::string::npos) << msg;  // names the line's key
  std::string k = text;
  k.replace(k.find("codebook K 8"), 12, "codebook K 9");
  EXPECT_NE(load_error(write("k.txt", k)).find("K differs"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// Found by the head_model fuzz harness: a seed or an utterance count beyond
// what the integer holds was cast anyway (undefined behaviour), instead of
// being an error at its line.
TEST(ModelFile, SeedAndCountsOutOfTheirIntegerRangeAreClearErrors) {
  std::stringstream buf;
  buf << std::ifstream(std::string(ANIMRT_SOURCE_DIR) + "/configs/head/model.txt").rdbuf();
  const std::string text = buf.str();
  const std::string dir = test::temp_dir("rangemodel");
  auto replaced = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) t.replace(at, from.size(), to);
    std::ofstream(dir + "/" + name) << t;
    return dir + "/" + name;
  };
  const std::string seed =
      load_error(replaced("seed.txt", "seed 1\n",
                          "seed 777777777777777777777777777777777777777777777777777777777771\n"));
  EXPECT_NE(seed.find(":4:"), std::string::npos) << seed;
  EXPECT_NE(seed.find("seed: expected a whole number"), std::string::npos) << seed;
  EXPECT_NE(load_error(replaced("negative.txt", "seed 1\n", "seed -1\n")).find("seed: expected"),
            std::string::npos);
  const std::string count =
      load_error(replaced("count.txt", "utterances 32\n", "utterances 1e300\n"));
  EXPECT_NE(count.find(":8:"), std::string::npos) << count;
  EXPECT_NE(count.find("expected a count"), std::string::npos) << count;
  EXPECT_NO_THROW(load_model(replaced("ok.txt", "seed 1\n", "seed 18446744073709549568\n")));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace animrt::head
