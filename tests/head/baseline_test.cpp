// The learner against the simplest competitor: a head that always shows the
// mean training pose. On held-out utterances of a generated corpus with four
// speaker styles, the trained model must be closer to the original motion
// and more correlated with it than that baseline, and its correlation must
// come from the speech of the utterance it was given (pairing the synthesized
// motion with another utterance's original must correlate less).

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "animrt/controllers/head/corpus.hpp"
#include "animrt/controllers/head/evaluation.hpp"
#include "animrt/controllers/head/synthesis.hpp"
#include "animrt/controllers/head/trainer.hpp"
#include "head_test_util.hpp"

namespace animrt::head {
namespace {

struct FourSpeakers {
  std::vector<PreparedUtterance> train, test;
  HeadModel model;
};

const FourSpeakers& four_speakers() {
  static const FourSpeakers f = [] {
    const std::string dir = test::temp_dir("corpus4");
    sim::head_corpus::CorpusOptions co;
    co.utterances = 40;
    co.speakers = 4;
    co.seed = 7;
    sim::head_corpus::generate_corpus(dir, co);
    FourSpeakers out;
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
  }();
  return f;
}

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
  const FourSpeakers& f = four_speakers();
  ASSERT_EQ(f.train.size(), 32u);
  ASSERT_EQ(f.test.size(), 8u);
  const Evaluation e = evaluate(f.model, f.test, mean_pose(f.train));
  ASSERT_EQ(e.utterances, 8);
  EXPECT_LT(e.distance_deg.mean, e.baseline_distance_deg.mean)
      << "model " << e.distance_deg.mean << " deg, mean pose " << e.baseline_distance_deg.mean;
  EXPECT_GT(e.cca.mean, e.baseline_cca.mean)
      << "model " << e.cca.mean << ", mean pose " << e.baseline_cca.mean;

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
  std::printf("held out: distance %.2f deg (mean pose %.2f), CCA %.3f (mean pose %.3f, "
              "mismatched %.3f)\n",
              e.distance_deg.mean, e.baseline_distance_deg.mean, e.cca.mean, e.baseline_cca.mean,
              mismatched / static_cast<double>(n));
  EXPECT_GT(matched / static_cast<double>(n), mismatched / static_cast<double>(n) + 0.1)
      << "matched " << matched / n << ", mismatched " << mismatched / n;
}

}  // namespace
}  // namespace animrt::head
