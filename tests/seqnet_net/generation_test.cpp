// Generation from initial frames with a tiny trained mesh model: frame
// counts over chained windows, the initial frames kept, repeatable for a
// random-state seed and different between seeds, other meshes refused;
// generated and completed frames follow the given frames' translation.

#include "animrt/controllers/seqnet/generation.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/shapes.hpp"
#include "animrt/learn/seqnet/training.hpp"
#include "net_test_util.hpp"

namespace animrt::seqnet {
namespace {

class SeqGeneration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    TrainOptions o = nettest::tiny_options(
        nettest::write_bar_features("gen_bar.features", 4, 6, 40), "gen_bar.model");
    o.iterations = 5;
    o.batch = 2;
    std::ostringstream log;
    train(o, log);
    model_path_ = o.out;
  }
  void SetUp() override {
    model_ = read_model_file(model_path_);
    bar_ = make_bar(4, 6, 4.0);
  }
  static inline std::string model_path_;
  ModelFile model_;
  MeshSequence bar_;
};

TEST_F(SeqGeneration, ChainsWindowsToTheRequestedLengthKeepingTheInitialFrames) {
  GenerateOptions o;
  o.frames = 19;  // more than two windows of 8
  const Positions first = bar_.frames[0];
  Positions second = first;
  second.row(1).array() += 0.05 * second.row(2).array();
  const auto out = generate_mesh(model_, model_path_, {first, second}, bar_.triangles, o);
  ASSERT_EQ(out.size(), 21U);
  EXPECT_TRUE(out[0].isApprox(first, 0.0));
  EXPECT_TRUE(out[1].isApprox(second, 0.0));
  for (const Positions& p : out) {
    ASSERT_EQ(p.cols(), first.cols());
    EXPECT_TRUE(p.allFinite());
  }
}

TEST_F(SeqGeneration, RandomStatesRepeatForASeedAndDifferBetweenSeeds) {
  GenerateOptions o;
  o.frames = 6;
  const auto plain = generate_mesh(model_, model_path_, {bar_.frames[0]}, bar_.triangles, o);
  const auto plain_again = generate_mesh(model_, model_path_, {bar_.frames[0]}, bar_.triangles, o);
  o.random_state = 1;
  const auto one = generate_mesh(model_, model_path_, {bar_.frames[0]}, bar_.triangles, o);
  const auto one_again = generate_mesh(model_, model_path_, {bar_.frames[0]}, bar_.triangles, o);
  o.random_state = 2;
  const auto two = generate_mesh(model_, model_path_, {bar_.frames[0]}, bar_.triangles, o);
  for (std::size_t k = 0; k < plain.size(); ++k) {
    EXPECT_TRUE(plain[k].isApprox(plain_again[k], 0.0)) << k;
    EXPECT_TRUE(one[k].isApprox(one_again[k], 0.0)) << k;
  }
  EXPECT_GT((one.back() - two.back()).norm(), 1e-9);
  EXPECT_GT((one.back() - plain.back()).norm(), 1e-9);
}

TEST_F(SeqGeneration, FramesOfAnotherMeshOrTooManyAreRefused) {
  GenerateOptions o;
  const MeshSequence sphere = make_icosphere(1);
  try {
    generate_mesh(model_, model_path_, {sphere.frames[0]}, sphere.triangles, o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(model_path_ + ": mesh: trained on a mesh of 26 vertices, "
                                                       "the data has 42"),
              std::string::npos)
        << e.what();
  }
  std::vector<Positions> many(8, bar_.frames[0]);
  EXPECT_THROW(generate_mesh(model_, model_path_, many, bar_.triangles, o), InputError);
}

TEST_F(SeqGeneration, GeneratedFramesFollowTheInitialFramesTranslation) {
  GenerateOptions o;
  o.frames = 5;
  const Positions first = bar_.frames[0];
  const Eigen::Vector3d d(1.5, -2.0, 0.25);
  Positions moved = first;
  moved.colwise() += d;
  const auto here = generate_mesh(model_, model_path_, {first}, bar_.triangles, o);
  const auto there = generate_mesh(model_, model_path_, {moved}, bar_.triangles, o);
  ASSERT_EQ(here.size(), there.size());
  for (std::size_t k = 1; k < here.size(); ++k) {
    const Positions shift = there[k] - here[k];
    EXPECT_LT((shift.colwise() - d).cwiseAbs().maxCoeff(), 1e-6) << k;
  }
}

TEST_F(SeqGeneration, CompletedFramesFollowTheKeysTranslation) {
  const Positions key = bar_.frames[0];
  const Eigen::Vector3d d(0.0, 3.0, -1.0);
  Positions moved = key;
  moved.colwise() += d;
  const FrameMatrix features = mesh_features(model_, model_path_, {key, moved}, bar_.triangles);
  SeqNetInference net(model_, model_path_);
  const Completion c = net.complete(features, {4}, {.threshold = 0.05, .retries = 0, .seed = 1});
  const auto still = completed_mesh(model_, {key, key}, features, c, 4);
  const auto going = completed_mesh(model_, {key, moved}, features, c, 4);
  ASSERT_EQ(going.size(), 6U);
  EXPECT_TRUE(going.front().isApprox(key, 0.0));
  EXPECT_TRUE(going.back().isApprox(moved, 0.0));
  for (int t = 1; t <= 4; ++t) {
    const Positions shift = going[static_cast<std::size_t>(t)] - still[static_cast<std::size_t>(t)];
    EXPECT_LT((shift.colwise() - d * (t / 5.0)).cwiseAbs().maxCoeff(), 1e-6) << t;
  }
}

}  // namespace
}  // namespace animrt::seqnet
