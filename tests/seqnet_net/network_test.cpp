// The network's pieces: Eq. 2 on a hand-computed mesh, the shared parameter
// set of the two chains, and each loss term on hand-made tensors.

#include "animrt/learn/seqnet/network.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cmath>
#include <stdexcept>

namespace animrt::seqnet {
namespace {

class SeqNetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    torch::set_num_threads(1);
    torch::manual_seed(7);
  }
};

// Two triangles (0 1 2) and (0 2 3): rings 0:{1,2,3} 1:{0,2} 2:{0,1,3} 3:{0,2}.
const std::vector<std::array<int, 3>> kQuad = {{{0, 1, 2}}, {{0, 2, 3}}};

void set_weights(MeshConv& conv, double self, double ring, double bias) {
  torch::NoGradGuard no_grad;
  conv->self->weight.fill_(self);
  conv->self->bias.fill_(bias);
  conv->neighbours->weight.fill_(ring);
}

TEST_F(SeqNetTest, MeshConvolutionIsTheVertexPlusTheMeanOfItsRing) {
  MeshConv conv(1, 1, mesh_graph(4, kQuad), false);
  set_weights(conv, 2.0, 3.0, 0.5);
  const torch::Tensor x = torch::tensor({1.0F, 2.0F, 3.0F, 4.0F}).view({1, 4, 1});
  const torch::Tensor y = conv->forward(x).flatten();
  // means 3, 2, 7/3, 2: y = 2 x + 3 mean + 0.5
  const float expected[] = {11.5F, 10.5F, 13.5F, 14.5F};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(y[i].item<float>(), expected[i], 1e-5) << i;
}

TEST_F(SeqNetTest, TransposeConvolutionSpreadsWithTheAdjointWeights) {
  MeshConv conv(1, 1, mesh_graph(4, kQuad), true);
  const torch::Tensor x = torch::tensor({1.0F, 2.0F, 3.0F, 4.0F}).view({1, 4, 1});
  const torch::Tensor r = conv->ring(x).flatten();
  // vertex j collects x_i / d_i from every i whose ring holds j
  const float expected[] = {4.0F, 4.0F / 3, 10.0F / 3, 4.0F / 3};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(r[i].item<float>(), expected[i], 1e-5) << i;
  // <A x, y> = <x, A^T y> for random x, y
  MeshConv forward(1, 1, mesh_graph(4, kQuad), false);
  const torch::Tensor a = torch::randn({1, 4, 1}), b = torch::randn({1, 4, 1});
  EXPECT_NEAR((forward->ring(a) * b).sum().item<float>(), (a * conv->ring(b)).sum().item<float>(),
              1e-5);
}

TEST_F(SeqNetTest, MeshConvolutionSharesItsWeightsOverVerticesAndChannels) {
  MeshConv conv(2, 3, mesh_graph(4, kQuad), false);
  EXPECT_EQ(conv->self->weight.sizes(), (std::vector<std::int64_t>{3, 2}));
  EXPECT_EQ(conv->neighbours->weight.sizes(), (std::vector<std::int64_t>{3, 2}));
  // Every vertex with the same value and the same ring values gives the same output.
  const torch::Tensor x = torch::ones({2, 4, 2});
  const torch::Tensor y = conv->forward(x);
  EXPECT_TRUE(torch::allclose(y[0][0], y[1][3]));
  // Vertex 1 by hand: W1 x_1 + W2 mean(x_0, x_2) + b
  const torch::Tensor r = torch::randn({1, 4, 2});
  const torch::Tensor by_hand = torch::matmul(conv->self->weight, r[0][1]) + conv->self->bias +
                                torch::matmul(conv->neighbours->weight, (r[0][0] + r[0][2]) / 2);
  EXPECT_TRUE(torch::allclose(conv->forward(r)[0][1], by_hand, 1e-5, 1e-6));
}

NetShape small_joint_shape() {
  NetShape s;
  s.kind = ModelKind::joints;
  s.joint_count = 3;
  s.dense_width = 8;
  s.latent = 4;
  s.hidden = 6;
  s.lstm_layers = 3;
  return s;
}

TEST_F(SeqNetTest, ForwardAndBackwardChainsShareOneParameterSet) {
  SeqNet net(small_joint_shape(), MeshGraph{});
  EXPECT_FALSE(net->lstm->options.bidirectional());
  for (const auto& p : net->named_parameters()) {
    EXPECT_EQ(p.key().find("reverse"), std::string::npos) << p.key();
  }
  const torch::Tensor first = torch::rand({1, 2, 3}) - 0.5;
  const torch::Tensor last = torch::rand({1, 2, 3}) - 0.5;
  torch::NoGradGuard no_grad;
  const torch::Tensor f0 = net->run(first, 5, net->initial_state(2, 1.0), false).frames;
  const torch::Tensor b0 = net->run(last, 5, net->initial_state(2, -1.0), false).frames;
  // The states differ in sign: the same frame gives another chain.
  const torch::Tensor f_neg = net->run(first, 5, net->initial_state(2, -1.0), false).frames;
  EXPECT_FALSE(torch::allclose(f0, f_neg));
  // One parameter, changed, changes both chains.
  net->lstm->named_parameters()["weight_hh_l2"].add_(0.2);
  const torch::Tensor f1 = net->run(first, 5, net->initial_state(2, 1.0), false).frames;
  const torch::Tensor b1 = net->run(last, 5, net->initial_state(2, -1.0), false).frames;
  EXPECT_FALSE(torch::allclose(f0.slice(0, 1), f1.slice(0, 1)));
  EXPECT_FALSE(torch::allclose(b0.slice(0, 1), b1.slice(0, 1)));
  // The given frame comes back unchanged as the chain's first.
  EXPECT_TRUE(torch::equal(f1[0], first[0]));
}

TEST_F(SeqNetTest, ChainFeedsGivenFramesThenItsOwnOutput) {
  SeqNet net(small_joint_shape(), MeshGraph{});
  torch::NoGradGuard no_grad;
  const torch::Tensor given = torch::rand({3, 1, 3});
  const Chain c = net->run(given, 6, net->initial_state(1, 1.0), false);
  ASSERT_EQ(c.frames.size(0), 6);
  EXPECT_EQ(c.mu.size(0), 5);
  for (int t = 0; t < 3; ++t) EXPECT_TRUE(torch::equal(c.frames[t], given[t])) << t;
  // Generated: frame t+1 = frame t + decode(LSTM(encode(frame t)))
  EXPECT_FALSE(torch::allclose(c.frames[4], c.frames[3]));
}

TEST_F(SeqNetTest, MeshNetworkMapsFramesToFramesOfTheSameSize) {
  NetShape s;
  s.kind = ModelKind::mesh;
  s.vertex_count = 4;
  s.latent = 5;
  s.hidden = 7;
  SeqNet net(s, mesh_graph(4, kQuad));
  torch::NoGradGuard no_grad;
  const Chain c = net->run(torch::rand({1, 2, 36}), 4, net->initial_state(2, 1.0), false);
  EXPECT_EQ(c.frames.sizes(), (std::vector<std::int64_t>{4, 2, 36}));
  EXPECT_EQ(c.mu.sizes(), (std::vector<std::int64_t>{3, 2, 5}));
}

TEST_F(SeqNetTest, ReconstructionAndBidirectionalLossesByHand) {
  // n = 2 frames, B = 1, D = 2
  const torch::Tensor truth = torch::tensor({0.0F, 0.0F, 1.0F, 1.0F}).view({2, 1, 2});
  const torch::Tensor f = torch::tensor({0.0F, 0.0F, 1.0F, 3.0F}).view({2, 1, 2});
  const torch::Tensor b = torch::tensor({1.0F, 1.0F, 0.0F, 2.0F}).view({2, 1, 2});
  // forward: frame 2 off by (0, 2): mean square 2; backward against the
  // reversed truth: frame 2 off by (0, 2): 2
  EXPECT_FLOAT_EQ(recon_loss(f, b, truth).item<float>(), 4.0F);
  // f - reversed b = (0,-2), (0,2): 2 + 2
  EXPECT_FLOAT_EQ(bidir_loss(f, b).item<float>(), 4.0F);
  EXPECT_FLOAT_EQ(bidir_loss(f, f.flip(0)).item<float>(), 0.0F);
  EXPECT_FLOAT_EQ(recon_loss(truth, truth.flip(0), truth).item<float>(), 0.0F);
  // The last number weighed 3 (a placement number): each frame's (0, 2)
  // error is (1 * 0 + 3 * 4) / 2 = 6.
  const torch::Tensor w = frame_weights(2, 1, 3.0);
  ASSERT_TRUE(w.defined());
  EXPECT_FLOAT_EQ(recon_loss(f, b, truth, w).item<float>(), 12.0F);
  EXPECT_FLOAT_EQ(bidir_loss(f, b, w).item<float>(), 12.0F);
  EXPECT_FALSE(frame_weights(2, 1, 1.0).defined());
  EXPECT_THROW(frame_weights(2, 1, 0.0), std::invalid_argument);
  EXPECT_THROW(frame_weights(2, 1, std::nan("")), std::invalid_argument);
}

TEST_F(SeqNetTest, KlDivergenceByHand) {
  EXPECT_FLOAT_EQ(kl_loss(torch::zeros({2, 3}), torch::zeros({2, 3})).item<float>(), 0.0F);
  EXPECT_FLOAT_EQ(kl_loss(torch::ones({2, 3}), torch::zeros({2, 3})).item<float>(), 0.5F);
  const float half_ln2 = static_cast<float>(0.5 * (1.0 - std::log(2.0)));
  EXPECT_NEAR(kl_loss(torch::zeros({1, 1}), torch::full({1, 1}, std::log(2.0F))).item<float>(),
              half_ln2, 1e-6);
  // mean over entries: one entry of 0.5 among four
  EXPECT_FLOAT_EQ(kl_loss(torch::tensor({1.0F, 0.0F, 0.0F, 0.0F}), torch::zeros({4})).item<float>(),
                  0.125F);
}

TEST_F(SeqNetTest, L2IsTheMeanSquareOfTheWeightMatricesOnly) {
  torch::nn::Linear lin(2, 1);
  {
    torch::NoGradGuard no_grad;
    lin->weight.copy_(torch::tensor({3.0F, 4.0F}).view({1, 2}));
    lin->bias.fill_(10.0F);
  }
  EXPECT_FLOAT_EQ(l2_loss(*lin).item<float>(), 12.5F);
  // Its gradient, by autograd and added by hand (as the training step
  // does): 2 w / 2 entries, scaled; the bias gets none.
  (0.3 * l2_loss(*lin)).backward();
  const torch::Tensor by_autograd = lin->weight.grad().clone();
  EXPECT_NEAR(by_autograd[0][1].item<double>(), 1.2, 1e-6);
  EXPECT_FALSE(lin->bias.grad().defined());
  add_l2_gradient(*lin, 0.3);
  EXPECT_TRUE(torch::allclose(lin->weight.grad(), 2 * by_autograd, 1e-6, 0.0));
  EXPECT_FALSE(lin->bias.grad().defined());
}

TEST_F(SeqNetTest, BatchLossWeighsTheTermsAsThePaper) {
  SeqNet net(small_joint_shape(), MeshGraph{});
  const torch::Tensor truth = torch::rand({6, 2, 3}) - 0.5;
  const LossTerms l = batch_loss(net, truth, false);
  const double expected = l.recon.item<double>() + 0.5 * l.bidir.item<double>() +
                          0.1 * (l.kl.item<double>() + l.l2.item<double>());
  EXPECT_NEAR(l.total.item<double>(), expected, 1e-5);
  EXPECT_GT(l.recon.item<double>(), 0.0);
  EXPECT_GT(l.bidir.item<double>(), 0.0);
  EXPECT_GT(l.kl.item<double>(), 0.0);
  EXPECT_GT(l.l2.item<double>(), 0.0);
  // Gradients reach the parameters through both chains.
  l.total.backward();
  for (const auto& p : net->named_parameters()) {
    ASSERT_TRUE(p.value().grad().defined()) << p.key();
  }
  const LossTerms uni = batch_loss(net, truth, false, 0.0, false);
  EXPECT_EQ(uni.bidir.item<double>(), 0.0);
  EXPECT_NEAR(uni.total.item<double>(), uni.recon.item<double>() + 0.1 * uni.l2.item<double>(),
              1e-5);
  // Without L2 (the third ablation) the weights are no longer in the total.
  const LossTerms no_l2 = batch_loss(net, truth, false, 1.0, true, 0.0);
  EXPECT_GT(no_l2.l2.item<double>(), 0.0);
  EXPECT_NEAR(
      no_l2.total.item<double>(),
      no_l2.recon.item<double>() + 0.5 * no_l2.bidir.item<double>() + 0.1 * no_l2.kl.item<double>(),
      1e-5);
}

TEST_F(SeqNetTest, AdamFollowsItsUpdateRule) {
  // One parameter, gradient 2 then -1: the first step moves by exactly lr
  // against the gradient's sign.
  torch::Tensor p = torch::zeros({1}, torch::requires_grad());
  Adam adam({p}, 0.1);
  (2.0 * p).sum().backward();
  adam.step();
  EXPECT_NEAR(p.item<float>(), -0.1F, 1e-6);
  (-1.0 * p).sum().backward();
  adam.step();
  // m = 0.9*0.2 + 0.1*(-1) = 0.08 -> /0.19; v = 0.999*0.004 + 0.001 = 0.004996 -> /0.001999
  const double m = 0.08 / 0.19, v = 0.004996 / (1.0 - 0.999 * 0.999);
  EXPECT_NEAR(p.item<float>(), -0.1 - 0.1 * m / (std::sqrt(v) + 1e-8), 1e-6);
  EXPECT_EQ(adam.steps(), 2);
  // Many entries (the update's vector body and its tail), three steps:
  // libtorch's operations on the same gradients give the same numbers.
  torch::manual_seed(2);
  torch::Tensor q = torch::randn({37}, torch::requires_grad());
  torch::Tensor q_ref = q.detach().clone(), m_ref = torch::zeros({37}), v_ref = torch::zeros({37});
  Adam many({q}, 0.01);
  for (int step = 1; step <= 3; ++step) {
    const torch::Tensor g = torch::randn({37});
    // The second step's gradient is a strided view (a gradient need not be
    // contiguous).
    q.mutable_grad() = step == 2 ? torch::stack({g, g}, 1).select(1, 0) : g.clone();
    ASSERT_EQ(q.grad().is_contiguous(), step != 2);
    many.step();
    EXPECT_EQ(q.grad().abs().max().item<float>(), 0.0F) << "the gradient is zeroed";
    m_ref.mul_(0.9).add_(g, 0.1);
    v_ref.mul_(0.999).addcmul_(g, g, 0.001);
    q_ref.addcdiv_(m_ref / (1.0 - std::pow(0.9, step)),
                   (v_ref / (1.0 - std::pow(0.999, step))).sqrt_().add_(1e-8), -0.01);
    EXPECT_TRUE(torch::allclose(q.detach(), q_ref, 1e-6, 1e-7)) << "step " << step;
  }
}

}  // namespace
}  // namespace animrt::seqnet
