// Completion between keys on the plain inference: the keys come back bit for
// bit, a hand-made model whose chains are known merges where they meet,
// retries happen (and the best run is kept) when the threshold is not
// reached, bad arguments are refused. Generation of joint frames keeps its
// initial frames and repeats for a seed.

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cstring>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/learn/seqnet/network.hpp"

namespace animrt::seqnet {
namespace {

ModelFile joint_model(int joints, std::uint64_t seed) {
  torch::manual_seed(seed);
  ModelFile m;
  m.shape.kind = ModelKind::joints;
  m.shape.joint_count = joints;
  m.shape.dense_width = 8;
  m.shape.latent = 6;
  m.shape.hidden = 10;
  m.shape.window = 8;
  for (int j = 0; j < joints; ++j) m.joint_names.push_back("j" + std::to_string(j));
  m.low.assign(static_cast<std::size_t>(joints), -0.95);
  m.high.assign(static_cast<std::size_t>(joints), 0.95);  // normalised = model units
  SeqNet net(m.shape, MeshGraph{});
  m.parameters = save_parameters(*net);
  return m;
}

// Every parameter 0 but the last layer's bias: every step adds `step` to the
// one joint, whatever the state, so the forward chain from a is a + step t
// and the backward chain from b is b + step (n + 1 - t) at frame t.
ModelFile constant_step_model(float step) {
  ModelFile m = joint_model(1, 1);
  for (NamedArray& a : m.parameters) {
    std::fill(a.values.begin(), a.values.end(), 0.0F);
    if (a.name == "decoder.4.bias") a.values = {step};
  }
  return m;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(SeqCompletion, ChainsMergeWhereTheyMeet) {
  SeqNetInference net(constant_step_model(0.1F), "m.model");
  FrameMatrix keys(1, 3);
  keys << 0.4, 0.0, 0.4;
  // Gap 1: 0.4 + 0.1 t meets 0.0 + 0.1 (10 - t) at t = 3. Gap 2: 0.1 t
  // meets 0.4 + 0.1 (10 - t) at t = 7.
  CompletionOptions handed_over;
  handed_over.blend = false;
  const Completion c = net.complete(keys, {9, 9}, handed_over);
  ASSERT_EQ(c.frames.cols(), 21);
  ASSERT_EQ(c.gaps.size(), 2U);
  EXPECT_TRUE(c.gaps[0].merged);
  EXPECT_EQ(c.gaps[0].frame, 3);
  EXPECT_EQ(c.gaps[0].tries, 1);
  EXPECT_EQ(c.gaps[0].gap, 9);
  EXPECT_LT(c.gaps[0].difference, 1e-6);
  EXPECT_EQ(c.gaps[1].frame, 7);
  const double first[] = {0.4, 0.5, 0.6, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0};
  for (int t = 0; t <= 10; ++t) EXPECT_NEAR(c.frames(0, t), first[t], 1e-6) << t;
  const double second[] = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.6, 0.5, 0.4};
  for (int t = 0; t <= 10; ++t) EXPECT_NEAR(c.frames(0, 10 + t), second[t], 1e-6) << t;
}

TEST(SeqCompletion, BlendedChainsWeighEachByItsNearnessToItsKey) {
  SeqNetInference net(constant_step_model(0.1F), "m.model");
  FrameMatrix keys(1, 2);
  keys << 0.4, 0.0;
  // Frame t of 9: (1 - t / 10) (0.4 + 0.1 t) + t / 10 (0.1 (10 - t)).
  const Completion c = net.complete(keys, {9});
  EXPECT_EQ(c.gaps[0].frame, 3);  // where they meet is still reported
  for (int t = 1; t <= 9; ++t) {
    const double s = t / 10.0;
    EXPECT_NEAR(c.frames(0, t), (1 - s) * (0.4 + 0.1 * t) + s * 0.1 * (10 - t), 1e-6) << t;
  }
}

// An untrained network whose output layer starts at zero (as training
// starts it) completes every gap as linear interpolation of its keys, so
// training starts from interpolation, not below it.
TEST(SeqCompletion, UntrainedNetworkWithZeroOutputInterpolatesLinearly) {
  ModelFile m = joint_model(3, 5);
  SeqNet zeroed(m.shape, MeshGraph{});
  zeroed->zero_output_layer();
  m.parameters = save_parameters(*zeroed);
  SeqNetInference net(m, "m.model");
  FrameMatrix keys(3, 3);
  keys << 0.5, -0.5, 0.9, 0.2, 0.3, -0.1, -0.4, 0.6, 0.0;
  const Completion c = net.complete(keys, {6, 3});
  ASSERT_EQ(c.frames.cols(), 12);
  for (int t = 1; t <= 6; ++t) {
    const double s = t / 7.0;
    const Eigen::VectorXd line = (1 - s) * keys.col(0) + s * keys.col(1);
    EXPECT_LT((c.frames.col(t) - line).cwiseAbs().maxCoeff(), 1e-6) << t;
  }
  for (int t = 1; t <= 3; ++t) {
    const Eigen::VectorXd line = (1 - t / 4.0) * keys.col(1) + t / 4.0 * keys.col(2);
    EXPECT_LT((c.frames.col(7 + t) - line).cwiseAbs().maxCoeff(), 1e-6) << t;
  }
  // The network's other layers are untouched: not every parameter is zero.
  double sum = 0;
  for (const NamedArray& a : m.parameters) {
    for (float v : a.values) sum += std::abs(v);
  }
  EXPECT_GT(sum, 1.0);
}

TEST(SeqCompletion, AGapThatDoesNotMeetIsRetriedAndReported) {
  SeqNetInference net(constant_step_model(0.1F), "m.model");
  FrameMatrix keys(1, 2);
  keys << 0.0, 0.0;
  // 0.1 t against 0.1 (5 - t): closest at t = 2 or 3, 0.1 apart, which is
  // 0.1 / 1.9 = 5.3 % of the range.
  CompletionOptions o;
  o.retries = 3;
  const Completion c = net.complete(keys, {4}, o);
  EXPECT_FALSE(c.gaps[0].merged);
  EXPECT_EQ(c.gaps[0].tries, 4);
  EXPECT_NEAR(c.gaps[0].difference, 0.1 / 1.9, 1e-6);
  o.threshold = 0.06;
  const Completion merged = net.complete(keys, {4}, o);
  EXPECT_TRUE(merged.gaps[0].merged);
  EXPECT_EQ(merged.gaps[0].tries, 1);
}

TEST(SeqCompletion, KeysComeBackBitForBit) {
  SeqNetInference net(joint_model(3, 7), "m.model");
  FrameMatrix keys(3, 3);
  keys << 0.123456789012345, -0.7, 2.5,  // the last outside the training range
      1.0 / 3.0, 0.1, -0.3, 0.9, 0.2, 1e-17;
  const Completion c = net.complete(keys, {3, 5});
  ASSERT_EQ(c.frames.cols(), 11);
  for (int j = 0; j < 3; ++j) {
    EXPECT_TRUE(same_bits(c.frames(j, 0), keys(j, 0))) << j;
    EXPECT_TRUE(same_bits(c.frames(j, 4), keys(j, 1))) << j;
    EXPECT_TRUE(same_bits(c.frames(j, 10), keys(j, 2))) << j;
  }
  EXPECT_TRUE(c.frames.allFinite());
  // The in-betweens are the network's, not copies of a key.
  EXPECT_GT((c.frames.col(2) - keys.col(0)).norm(), 1e-6);
}

TEST(SeqCompletion, TinyThresholdRetriesKeepingTheBestRun) {
  SeqNetInference net(joint_model(3, 8), "m.model");
  FrameMatrix keys(3, 2);
  keys << 0.5, -0.5, 0.2, 0.3, -0.4, 0.6;
  CompletionOptions o;
  o.threshold = 1e-12;
  o.retries = 0;
  const Completion once = net.complete(keys, {6}, o);
  EXPECT_EQ(once.gaps[0].tries, 1);
  EXPECT_FALSE(once.gaps[0].merged);
  o.retries = 6;
  const Completion many = net.complete(keys, {6}, o);
  EXPECT_EQ(many.gaps[0].tries, 7);
  EXPECT_FALSE(many.gaps[0].merged);
  EXPECT_LE(many.gaps[0].difference, once.gaps[0].difference);
  // The same seed repeats; another seed draws other states.
  const Completion again = net.complete(keys, {6}, o);
  EXPECT_EQ(again.frames, many.frames);
  o.seed = 2;
  const Completion other = net.complete(keys, {6}, o);
  EXPECT_NE(other.gaps[0].difference, many.gaps[0].difference);
}

TEST(SeqCompletion, BadArgumentsAreRefused) {
  SeqNetInference net(joint_model(3, 9), "m.model");
  const FrameMatrix keys = FrameMatrix::Zero(3, 3);
  EXPECT_THROW(net.complete(keys.leftCols(1), {}), std::invalid_argument);
  EXPECT_THROW(net.complete(keys, {4}), std::invalid_argument);
  EXPECT_THROW(net.complete(keys, {4, 0}), std::invalid_argument);
  EXPECT_THROW(net.complete(FrameMatrix::Zero(2, 3), {4, 4}), std::invalid_argument);
  CompletionOptions o;
  o.threshold = 0.0;
  EXPECT_THROW(net.complete(keys, {4, 4}, o), std::invalid_argument);
  o.threshold = std::nan("");
  EXPECT_THROW(net.complete(keys, {4, 4}, o), std::invalid_argument);
  o = {};
  o.retries = -1;
  EXPECT_THROW(net.complete(keys, {4, 4}, o), std::invalid_argument);
  try {
    net.complete(keys, {4});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "3 keys need 2 gaps, got 1");
  }
}

TEST(SeqGenerationJoints, KeepsTheInitialFramesAndRepeatsForASeed) {
  SeqNetInference net(joint_model(3, 10), "m.model");
  FrameMatrix initial(3, 2);
  initial << 0.3, 0.31, -0.2, -0.21, 0.7, 0.69;
  const FrameMatrix plain = net.generate(initial, 20);  // chains 3 windows of 8
  ASSERT_EQ(plain.cols(), 22);
  EXPECT_EQ(plain.leftCols(2), initial);
  EXPECT_TRUE(plain.allFinite());
  const FrameMatrix one = net.generate(initial, 20, 1);
  EXPECT_EQ(one, net.generate(initial, 20, 1));
  EXPECT_GT((one.col(21) - net.generate(initial, 20, 2).col(21)).norm(), 1e-9);
  EXPECT_GT((one.col(21) - plain.col(21)).norm(), 1e-9);
  EXPECT_THROW(net.generate(FrameMatrix::Zero(3, 8), 4), std::invalid_argument);
}

}  // namespace
}  // namespace animrt::seqnet
