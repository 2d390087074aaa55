// The training step's shortcuts compute what the plain formulation does:
// both chains in one batch give the loss of two separate runs, and the
// dense layers' weight gradients formed once after backward equal
// autograd's per-step sum.

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <numbers>
#include <tuple>
#include <utility>

#include "animrt/learn/seqnet/dense_kernel.hpp"
#include "animrt/learn/seqnet/lstm_step.hpp"
#include "animrt/learn/seqnet/mesh_conv_kernel.hpp"
#include "animrt/learn/seqnet/network.hpp"
#include "animrt/learn/seqnet/shapes.hpp"

namespace animrt::seqnet {
namespace {

struct SmallMesh {
  MeshSequence bar = make_twisting_bar(4, 6, 2.0, std::numbers::pi, 1);
  NetShape shape;
  SmallMesh() {
    shape.kind = ModelKind::mesh;
    shape.vertex_count = bar.vertex_count();
    shape.latent = 8;
    shape.hidden = 12;
    shape.lstm_layers = 2;
  }
  SeqNet net(std::uint64_t seed) const {
    torch::manual_seed(seed);
    return SeqNet(shape, mesh_graph(bar.vertex_count(), bar.triangles));
  }
};

double worst_relative(const torch::Tensor& a, const torch::Tensor& b) {
  return (a - b).abs().max().item<double>() / std::max(1e-12, b.abs().max().item<double>());
}

TEST(SeqTrainingStep, BothChainsInOneBatchGiveTheLossOfTwoSeparateRuns) {
  torch::set_num_threads(1);
  const SmallMesh m;
  SeqNet net = m.net(3);
  const torch::Tensor truth = torch::rand({6, 3, m.shape.input_dims()}) * 1.9 - 0.95;
  torch::NoGradGuard no_grad;
  const LossTerms l = batch_loss(net, truth, false);
  const Chain f = net->run(truth.slice(0, 0, 1), 6, net->initial_state(3, 1.0), false);
  const Chain b = net->run(truth.slice(0, 5, 6), 6, net->initial_state(3, -1.0), false);
  EXPECT_NEAR(l.recon.item<double>(), recon_loss(f.frames, b.frames, truth).item<double>(),
              1e-5 * l.recon.item<double>());
  EXPECT_NEAR(l.bidir.item<double>(), bidir_loss(f.frames, b.frames).item<double>(),
              1e-5 * l.bidir.item<double>());
  const double kl = 0.5 * (kl_loss(f.mu, f.logvar) + kl_loss(b.mu, b.logvar)).item<double>();
  EXPECT_NEAR(l.kl.item<double>(), kl, 1e-5 * kl);
  EXPECT_GT(l.bidir.item<double>(), 0.0);
}

TEST(SeqTrainingStep, ChainLossesComputeWhatReconAndBidirLossDo) {
  // An odd number of frames (the middle one meets itself reversed) and
  // rows of 37 (the loops' vector body and tail); unweighted, and with the
  // last numbers of a frame weighted as --placement-weight does.
  torch::manual_seed(17);
  const torch::Tensor truth = torch::rand({5, 3, 37}) - 0.5;
  const torch::Tensor frames0 = torch::rand({5, 6, 37}) - 0.5;
  const auto run = [&](bool fused, double recon_weight, double bidir_weight,
                       const torch::Tensor& weight) {
    const torch::Tensor frames = frames0.clone().requires_grad_(true);
    torch::Tensor recon, bidir;
    if (fused) {
      std::tie(recon, bidir) = chain_losses(frames, truth, weight);
    } else {
      const torch::Tensor f = frames.slice(1, 0, 3), b = frames.slice(1, 3);
      recon = recon_loss(f, b, truth, weight);
      bidir = bidir_loss(f, b, weight);
    }
    (recon_weight * recon + bidir_weight * bidir).backward();
    return std::tuple{recon.item<double>(), bidir.item<double>(), frames.grad()};
  };
  const torch::Tensor placement = frame_weights(37, 9, 100.0);
  double unweighted = 0.0;
  for (const torch::Tensor& weight : {torch::Tensor(), placement}) {
    for (const auto& [wr, wb] : {std::pair{1.0, 0.5}, std::pair{0.0, 1.0}, std::pair{1.0, 0.0}}) {
      const auto [recon, bidir, grad] = run(true, wr, wb, weight);
      const auto [recon_ref, bidir_ref, grad_ref] = run(false, wr, wb, weight);
      EXPECT_NEAR(recon, recon_ref, 1e-6 * recon_ref);
      EXPECT_NEAR(bidir, bidir_ref, 1e-6 * bidir_ref);
      EXPECT_LT(worst_relative(grad, grad_ref), 1e-5) << wr << " " << wb << " " << weight.defined();
      if (!weight.defined() && wr == 1.0 && wb == 0.5) unweighted = recon;
      // The weight counts: 9 of 37 numbers at 100 are many times the sum.
      if (weight.defined() && wr == 1.0 && wb == 0.5) {
        EXPECT_GT(recon, 10.0 * unweighted);
      }
    }
  }
}

// Every parameter's gradient, plain autograd against the collected path.
void expect_same_gradients(SeqNet& plain, SeqNet& collected) {
  const auto a = plain->named_parameters();
  const auto b = collected->named_parameters();
  ASSERT_EQ(a.size(), b.size());
  for (const auto& item : a) {
    const torch::Tensor ga = item.value().grad();
    const torch::Tensor gb = b[item.key()].grad();
    ASSERT_TRUE(ga.defined() && gb.defined()) << item.key();
    EXPECT_EQ(gb.scalar_type(), torch::kFloat32) << item.key();
    EXPECT_GT(ga.abs().max().item<double>(), 0.0) << item.key();
    EXPECT_LT(worst_relative(gb, ga), 1e-4) << item.key();
  }
}

TEST(SeqTrainingStep, CollectedDenseGradientsEqualAutogradsSum) {
  torch::set_num_threads(1);
  const SmallMesh m;
  SeqNet plain = m.net(5), collected = m.net(5);
  const torch::Tensor truth = torch::rand({7, 2, m.shape.input_dims()}) * 1.9 - 0.95;
  batch_loss(plain, truth, false).total.backward();
  collected->collect_dense_gradients(true);
  const LossTerms l = batch_loss(collected, truth, false);
  collected->collect_dense_gradients(false);
  l.total.backward();
  // Before finishing, the dense layers have only the L2 term's gradient.
  EXPECT_GT(worst_relative(collected->to_mu->weight.grad(), plain->to_mu->weight.grad()), 0.1);
  collected->finish_gradients();
  expect_same_gradients(plain, collected);
}

TEST(SeqTrainingStep, StepsFedGivenFramesAreLeftOutOfTheCollectedGradients) {
  // With 3 given frames the decoder's output at the first two steps is
  // discarded: no gradient reaches it there.
  torch::set_num_threads(1);
  const SmallMesh m;
  SeqNet plain = m.net(9), collected = m.net(9);
  const torch::Tensor given = torch::rand({3, 2, m.shape.input_dims()}) - 0.5;
  auto loss = [&](SeqNet& net) {
    const Chain c = net->run(given, 6, net->initial_state(2, 1.0), false);
    return c.frames.pow(2).sum() + c.mu.sum() + c.logvar.exp().sum();
  };
  loss(plain).backward();
  collected->collect_dense_gradients(true);
  const torch::Tensor l = loss(collected);
  collected->collect_dense_gradients(false);
  l.backward();
  collected->finish_gradients();
  expect_same_gradients(plain, collected);
}

TEST(SeqTrainingStep, TrainStepUpdatesFloatParametersFromTheCollectedGradients) {
  torch::set_num_threads(1);
  const SmallMesh m;
  SeqNet plain = m.net(11), stepped = m.net(11);
  const torch::Tensor truth = torch::rand({5, 2, m.shape.input_dims()}) * 1.9 - 0.95;
  Adam adam_plain(plain->parameters(), 1e-3), adam(stepped->parameters(), 1e-3);
  // The same latent draws for both: train_step samples, so seed before each.
  torch::manual_seed(1);
  batch_loss(plain, truth, true).total.backward();
  adam_plain.step();
  torch::manual_seed(1);
  train_step(stepped, adam, truth);
  for (const auto& item : plain->named_parameters()) {
    const torch::Tensor p = stepped->named_parameters()[item.key()];
    EXPECT_EQ(p.scalar_type(), torch::kFloat32) << item.key();
    // One Adam step moves every weight by about the step size; the two
    // agree far closer than that.
    EXPECT_LT((p - item.value()).abs().max().item<double>(), 1e-5) << item.key();
  }
}

// Clipping scales every gradient by one factor, and only when all of them
// together are longer than the limit; a train_step whose gradients stay
// under it moves the weights exactly as one without clipping.
TEST(SeqTrainingStep, ClippingScalesAllGradientsTogetherOnlyWhenLonger) {
  torch::set_num_threads(1);
  const SmallMesh m;
  SeqNet net = m.net(5);
  Adam adam(net->parameters(), 1e-3);
  double count = 0;
  for (torch::Tensor& p : net->parameters()) {
    p.mutable_grad() = torch::full_like(p, 0.5);
    count += static_cast<double>(p.numel());
  }
  const double norm = 0.5 * std::sqrt(count);
  EXPECT_NEAR(adam.clip(2 * norm), norm, 1e-9 * norm);
  for (const torch::Tensor& p : net->parameters()) EXPECT_EQ(p.grad().max().item<float>(), 0.5f);
  EXPECT_NEAR(adam.clip(norm / 4), norm, 1e-9 * norm);
  for (const torch::Tensor& p : net->parameters()) {
    EXPECT_NEAR(p.grad().min().item<double>(), 0.125, 1e-7);
    EXPECT_NEAR(p.grad().max().item<double>(), 0.125, 1e-7);
  }

  SeqNet plain = m.net(11), roomy = m.net(11), tight = m.net(11);
  const torch::Tensor truth = torch::rand({5, 2, m.shape.input_dims()}) * 1.9 - 0.95;
  Adam adam_plain(plain->parameters(), 1e-3), adam_roomy(roomy->parameters(), 1e-3),
      adam_tight(tight->parameters(), 1e-3);
  torch::manual_seed(1);
  EXPECT_EQ(train_step(plain, adam_plain, truth).gradient_norm, 0.0);  // not computed
  torch::manual_seed(1);
  const double seen = train_step(roomy, adam_roomy, truth, 1, true, 1, {}, 1e9).gradient_norm;
  EXPECT_GT(seen, 0.0);
  torch::manual_seed(1);
  EXPECT_NEAR(train_step(tight, adam_tight, truth, 1, true, 1, {}, seen / 100).gradient_norm, seen,
              1e-9 * seen);
  // A second step: Adam's first step moves each weight by the step size
  // whatever the gradient's length, its second one by the moments.
  torch::manual_seed(2);
  train_step(plain, adam_plain, truth);
  torch::manual_seed(2);
  train_step(roomy, adam_roomy, truth, 1, true, 1, {}, 1e9);
  torch::manual_seed(2);
  train_step(tight, adam_tight, truth, 1, true, 1, {}, seen / 100);
  double apart = 0;
  for (const auto& item : plain->named_parameters()) {
    EXPECT_TRUE(torch::equal(roomy->named_parameters()[item.key()], item.value())) << item.key();
    apart = std::max(apart, (tight->named_parameters()[item.key()] - item.value())
                                .abs()
                                .max()
                                .item<double>());
  }
  EXPECT_GT(apart, 1e-5);
}

// One fused node per convolution (and its tanh), the loops of
// mesh_conv_kernel.hpp on [V, C, B], against the layer-by-layer
// formulation of libtorch's ops (sparse product, two products and bias on
// [V, B, C]): the same output and the same gradients, both directions.
void expect_fused_equals_plain(const MeshSequence& bar, int batch, bool transpose, bool squash) {
  torch::manual_seed(13);
  const MeshGraph graph = mesh_graph(bar.vertex_count(), bar.triangles);
  MeshConv conv(9, 7, graph, transpose);
  const torch::Tensor x0 = torch::rand({bar.vertex_count(), batch, 9}) * 2 - 1;
  const torch::Tensor weights = torch::rand({bar.vertex_count(), batch, 7});
  auto run = [&](bool fused) {
    conv->zero_grad();
    const torch::Tensor x = x0.clone().requires_grad_();
    torch::Tensor y;
    if (fused) {
      y = conv->forward_fused(x.permute({0, 2, 1}).contiguous(), squash).permute({0, 2, 1});
    } else {
      y = conv->forward_vertices_first(x);
      if (squash) y = torch::tanh(y);
    }
    (y * weights).sum().backward();
    std::vector<torch::Tensor> out{y.detach(), x.grad()};
    for (const auto& p : conv->parameters()) out.push_back(p.grad().clone());
    return out;
  };
  const auto plain = run(false), fused = run(true);
  ASSERT_EQ(plain.size(), 5U);
  for (std::size_t k = 0; k < plain.size(); ++k) {
    EXPECT_GT(plain[k].abs().max().item<double>(), 0.0) << k;
    EXPECT_LT(worst_relative(fused[k], plain[k]), 1e-5)
        << "output/x/W1/b/W2 " << k << ", batch " << batch << ", transpose " << transpose
        << ", squash " << squash;
  }
}

TEST(SeqTrainingStep, FusedConvolutionComputesWhatItsLayersDo) {
  torch::set_num_threads(1);
  const SmallMesh m;
  for (bool transpose : {false, true}) {
    for (bool squash : {false, true}) expect_fused_equals_plain(m.bar, 3, transpose, squash);
  }
  // 9 input channels and a batch of whole vectors run with the channels in
  // registers: here two vectors per vertex.
  for (bool transpose : {false, true}) expect_fused_equals_plain(m.bar, 32, transpose, true);
}

// At the training batch (16, a whole vector) and an odd one, on a mesh
// large enough that two threads split its vertices and add up two sets of
// weight gradients.
TEST(SeqTrainingStep, FusedConvolutionSplitBetweenThreadsComputesWhatItsLayersDo) {
  const MeshSequence bar = make_twisting_bar(12, 20, 4.0, std::numbers::pi, 1);
  ASSERT_GT(bar.vertex_count(), 200);
  torch::set_num_threads(2);
  // The suite runs in one process after cases that set one thread: a
  // thread pool that ignored the second setting would run this on one.
  EXPECT_EQ(at::get_num_threads(), 2);
  expect_fused_equals_plain(bar, 16, false, true);
  expect_fused_equals_plain(bar, 5, true, true);
  torch::set_num_threads(1);
}

// The dense layers' loops on [K, B] against libtorch's product: W x + b
// and W^T g (W packed by its transpose's strides), 21 output rows (two
// blocks and a partial one) at a batch of a whole vector and five more.
TEST(SeqTrainingStep, BatchInnerDenseProductsComputeWhatLibtorchDoes) {
  torch::manual_seed(17);
  const int rows = 21, cols = 37, batch = 21;
  const torch::Tensor w = torch::rand({rows, cols}) - 0.5;
  const torch::Tensor bias = torch::rand({rows});
  const torch::Tensor x = torch::rand({cols, batch}) - 0.5, g = torch::rand({rows, batch}) - 0.5;
  const auto blocks = (rows + kDenseRows - 1) / kDenseRows;
  const auto t_blocks = (cols + kDenseRows - 1) / kDenseRows;
  std::vector<float> packed(dense_packed_size(rows, cols)), t_packed(dense_packed_size(cols, rows));
  pack_dense_rows(w.data_ptr<float>(), rows, cols, cols, 1, packed.data());
  pack_dense_rows(w.data_ptr<float>(), cols, rows, 1, cols, t_packed.data());
  torch::Tensor y = torch::full({rows, batch}, 7.0F), gx = torch::full({cols, batch}, 7.0F);
  // In two calls, as two threads split the blocks.
  dense_batch_inner(packed.data(), bias.data_ptr<float>(), x.data_ptr<float>(), rows, cols, batch,
                    y.data_ptr<float>(), 0, 1);
  dense_batch_inner(packed.data(), bias.data_ptr<float>(), x.data_ptr<float>(), rows, cols, batch,
                    y.data_ptr<float>(), 1, blocks);
  dense_batch_inner(t_packed.data(), nullptr, g.data_ptr<float>(), cols, rows, batch,
                    gx.data_ptr<float>(), 0, t_blocks);
  EXPECT_LT(worst_relative(y, torch::addmm(bias.unsqueeze(1), w, x)), 1e-6);
  EXPECT_LT(worst_relative(gx, torch::mm(w.t(), g)), 1e-6);
}

// The rows of a sparse matrix as the kernel walks them: columns ascending,
// a pair given twice summed, a vertex without neighbours an empty row.
TEST(SeqTrainingStep, RingRowsSortAndSumLikeACoalescedSparseMatrix) {
  const RingRows m =
      ring_rows(4, {2, 0, 2, 0, 2}, {3, 1, 0, 1, 1}, {1.0F, 0.5F, 2.0F, 0.25F, 4.0F});
  EXPECT_EQ(m.start, (std::vector<std::int32_t>{0, 1, 1, 4, 4}));
  EXPECT_EQ(m.col, (std::vector<std::int32_t>{1, 0, 1, 3}));
  EXPECT_EQ(m.weight, (std::vector<float>{0.75F, 2.0F, 4.0F, 1.0F}));
}

// The fused LSTM step (one node per step, lstm_step.hpp) against
// libtorch's LSTM over three chained steps: the states, and the gradients
// of the inputs, of the initial state and of every weight (formed from
// the pack after backward), for a loss that reaches every step's h and the
// last c.
TEST(SeqTrainingStep, FusedLstmStepComputesWhatLibtorchsLstmDoes) {
  torch::set_num_threads(1);
  torch::manual_seed(23);
  const int layers = 2, in = 5, hidden = 7, batch = 19, steps = 3;
  torch::nn::LSTM plain(torch::nn::LSTMOptions(in, hidden).num_layers(layers));
  torch::nn::LSTM fused(torch::nn::LSTMOptions(in, hidden).num_layers(layers));
  {
    torch::NoGradGuard no_grad;
    for (const auto& item : plain->named_parameters()) {
      fused->named_parameters()[item.key()].copy_(item.value());
    }
  }
  const torch::Tensor z = torch::randn({steps, batch, in});
  const torch::Tensor h0 = torch::randn({layers, batch, hidden}) * 0.5;
  const torch::Tensor c0 = torch::randn({layers, batch, hidden}) * 2.0;
  const torch::Tensor wh = torch::randn({steps, batch, hidden}), wc = torch::randn(c0.sizes());
  struct Run {
    torch::Tensor z, h0, c0, loss, h, c;
  };
  auto leaves = [&] {
    return Run{z.clone().requires_grad_(),
               h0.clone().requires_grad_(),
               c0.clone().requires_grad_(),
               {},
               {},
               {}};
  };
  Run a = leaves(), b = leaves();
  std::tuple<torch::Tensor, torch::Tensor> state{a.h0, a.c0};
  a.loss = torch::zeros({});
  for (int t = 0; t < steps; ++t) {
    auto [out, next] = plain->forward(a.z[t].unsqueeze(0), state);
    state = next;
    a.loss = a.loss + (out.squeeze(0) * wh[t]).sum();
  }
  std::tie(a.h, a.c) = state;
  a.loss = a.loss + (a.c * wc).sum();
  // The fused step's states have the batch innermost, [layers, hidden, B].
  const c10::intrusive_ptr<LstmPack> pack = pack_lstm(*fused);
  b.h = b.h0.transpose(1, 2);
  b.c = b.c0.transpose(1, 2);
  b.loss = torch::zeros({});
  for (int t = 0; t < steps; ++t) {
    std::tie(b.h, b.c) = lstm_step(b.z[t], b.h, b.c, pack);
    b.loss = b.loss + (b.h[layers - 1].t() * wh[t]).sum();
  }
  b.h = b.h.transpose(1, 2);
  b.c = b.c.transpose(1, 2);
  b.loss = b.loss + (b.c * wc).sum();
  EXPECT_LT(worst_relative(b.h, a.h), 1e-5);
  EXPECT_LT(worst_relative(b.c, a.c), 1e-5);
  a.loss.backward();
  b.loss.backward();
  EXPECT_LT(worst_relative(b.z.grad(), a.z.grad()), 1e-5);
  EXPECT_LT(worst_relative(b.h0.grad(), a.h0.grad()), 1e-5);
  EXPECT_LT(worst_relative(b.c0.grad(), a.c0.grad()), 1e-5);
  // The weights are outside autograd: their gradients come from the pack.
  const auto grads = lstm_gradients(*pack);
  ASSERT_EQ(grads.size(), 4U * layers);
  for (const auto& [name, g] : grads) {
    const torch::Tensor want = plain->named_parameters()[name].grad();
    ASSERT_TRUE(want.defined()) << name;
    EXPECT_GT(want.abs().max().item<double>(), 0.0) << name;
    EXPECT_LT(worst_relative(g, want), 1e-5) << name;
    EXPECT_FALSE(fused->named_parameters()[name].grad().defined()) << name;
  }
}

}  // namespace
}  // namespace animrt::seqnet
