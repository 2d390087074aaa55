// The learner against the simplest competitor: a head that always shows the
// mean training pose. On held-out utterances of generated corpora with four
// speaker styles (three corpus seeds), the trained model must be closer to
// the original motion and more correlated with it than that baseline, and its
// correlation must come from the speech of the utterance it was given
// (pairing the synthesized motion with another utterance's original must
// correlate less).

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>

#include "animrt/controllers/head/synthesis.hpp"
#include "animrt/learn/head/corpus.hpp"
#include "animrt/learn/head/evaluation.hpp"
#include "animrt/learn/head/trainer.hpp"
#include "head_test_util.hpp"

namespace animrt::head {
namespace {

struct FourSpeakers {
  std::uint64_t corpus_seed = 0;
  std::vector<PreparedUtterance> train, test;
  HeadModel model;
};

FourSpeakers make_four_speakers(std::uint64_t corpus_seed) {
  const std::string dir = test::temp_dir("corpus4");
  learn::head_corpus::CorpusOptions co;
  co.utterances = 40;
  co.speakers = 4;
  co.seed = corpus_seed;
  learn::head_corpus::generate_corpus(dir, co);
  FourSpeakers out;
  out.corpus_seed = corpus_seed;
  const auto split = split_corpus(list_corpus(dir), 0.8, 1);
  const FeatureConfig fc;
  out.train = prepare_corpus(split.train, fc);
  out.test = prepare_corpus(split.test, fc);
  TrainOptions o;  // the paper's K=16 S=3 M=2 left-to-right
  o.clusters = 16;
  o.states = 3;
  o.mixtures = 2;
  out.model = train_model(out.train, fc, o);
  std::filesystem::remove_all(dir);
  return out;
}

// One trained model per corpus seed, built on first use (each test process
// builds only the seeds its test needs).
const FourSpeakers& four_speakers(std::uint64_t seed) {
  static std::map<std::uint64_t, FourSpeakers> built;
  auto it = built.find(seed);
  if (it == built.end()) it = built.emplace(seed, make_four_speakers(seed)).first;
  return it->second;
}

// Corpus seeds 7, 1 and 3: on 1 and 3 the model lost to the mean pose when it
// output the paper's cluster means (shrink 1). The sanitizer build, many
// times slower, checks seed 7 only; the release build checks all three.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kBaselineSeeds[] = {7};
#else
constexpr std::uint64_t kBaselineSeeds[] = {7, 1, 3};
#endif

Eigen::MatrixXd synthesized_at_frames(const HeadModel& model, const PreparedUtterance& u) {
  const PoseTrack p = synthesize(model, u.track);
  Eigen::MatrixXd m(static_cast<Eigen::Index>(u.track.size()), 3);
  for (std::size_t i = 0; i < u.track.size(); ++i) {
    const Euler e = p.at(u.track.time(i));
    m.row(static_cast<Eigen::Index>(i)) << e.yaw, e.pitch, e.roll;
  }
  return m;
}

TEST(Training, BeatsTheMeanPoseBaselineOnHeldOutSpeech) {
  for (const std::uint64_t seed : kBaselineSeeds) {
    const FourSpeakers& f = four_speakers(seed);
    SCOPED_TRACE("corpus seed " + std::to_string(f.corpus_seed));
    ASSERT_EQ(f.train.size(), 32u);
    ASSERT_EQ(f.test.size(), 8u);
    const Evaluation e = evaluate(f.model, f.test, mean_pose(f.train));
    ASSERT_EQ(e.utterances, 8);
    std::printf(
        "corpus seed %llu held out: distance %.2f deg (mean pose %.2f), CCA %.3f (mean pose "
        "%.3f), shrink %.2f %.2f %.2f\n",
        static_cast<unsigned long long>(f.corpus_seed), e.distance_deg.mean,
        e.baseline_distance_deg.mean, e.cca.mean, e.baseline_cca.mean, f.model.smoothing.shrink(0),
        f.model.smoothing.shrink(1), f.model.smoothing.shrink(2));
    EXPECT_LT(e.distance_deg.mean, e.baseline_distance_deg.mean)
        << "model " << e.distance_deg.mean << " deg, mean pose " << e.baseline_distance_deg.mean;
    EXPECT_GT(e.cca.mean, e.baseline_cca.mean)
        << "model " << e.cca.mean << ", mean pose " << e.baseline_cca.mean;
  }
}

TEST(Training, CorrelationComesFromTheUtterancesOwnSpeech) {
  const FourSpeakers& f = four_speakers(7);
  // Chance level: each synthesized track against the next utterance's original.
  double matched = 0, mismatched = 0;
  const std::size_t n = f.test.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::MatrixXd s = synthesized_at_frames(f.model, f.test[i]);
    const PreparedUtterance& other = f.test[(i + 1) % n];
    const Eigen::Index rows = std::min(s.rows(), other.poses.rows());
    matched += first_canonical_correlation(s, f.test[i].poses);
    mismatched += first_canonical_correlation(s.topRows(rows), other.poses.topRows(rows));
  }
  std::printf("CCA matched %.3f, mismatched %.3f\n", matched / static_cast<double>(n),
              mismatched / static_cast<double>(n));
  EXPECT_GT(matched / static_cast<double>(n), mismatched / static_cast<double>(n) + 0.1)
      << "matched " << matched / n << ", mismatched " << mismatched / n;
}

TEST(Training, ShrinkMovesOutputPosesTowardTheMeanPosePerAxis) {
  const FourSpeakers& f = four_speakers(7);
  HeadModel m = f.model;
  m.smoothing.shrink = Eigen::Vector3d(0.0, 0.5, 1.0);
  for (int k = 0; k < m.clusters(); ++k) {
    const Eigen::Vector3d c = m.codebook.means.row(k).transpose();
    const Eigen::Vector3d p = m.cluster_pose(k);
    EXPECT_NEAR(p(0), m.pose_mean(0), 1e-12);
    EXPECT_NEAR(p(1), 0.5 * (c(1) + m.pose_mean(1)), 1e-12);
    EXPECT_NEAR(p(2), c(2), 1e-12);
  }
  // The chosen factors are factors, and chosen ones differ from the paper's 1.
  EXPECT_TRUE((f.model.smoothing.shrink.array() >= 0).all() &&
              (f.model.smoothing.shrink.array() <= 1).all());
  EXPECT_LT(f.model.smoothing.shrink.minCoeff(), 1.0);
}

}  // namespace
}  // namespace animrt::head
