#pragma once
// The share-weight bidirectional LSTM of "bdlstm-mesh-sequences" (sections
// 3.2-3.4) on libtorch: mesh convolutions (Eq. 2) encode a frame's features
// to a latent vector (mean and log-variance), a multi-layer LSTM steps it,
// transpose convolutions decode the change to the next frame. The joint-space
// variant puts dense layers where the mesh layers are. One parameter set runs
// the forward chain (state +s0) and the backward chain (state -s0).
// Only targets that link animrt_seqnet_torch include this header.

#include <torch/nn/module.h>
#include <torch/nn/modules/container/sequential.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/modules/rnn.h>

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/learn/seqnet/mesh_conv_kernel.hpp"

namespace animrt::seqnet {

// The directed 1-ring pairs (i, j) of a mesh with weight 1 / d_i, so that
// sum_j w_ij x_j is the mean of vertex i's neighbours.
struct MeshGraph {
  int vertex_count = 0;
  torch::Tensor rows;     // i, int64
  torch::Tensor cols;     // j, int64
  torch::Tensor weights;  // 1 / d_i, float
};
MeshGraph mesh_graph(int vertex_count, const std::vector<std::array<int, 3>>& triangles);

// A convolution's ring matrix M and its adjoint M^T by rows, shared with
// the autograd nodes of its steps.
struct MeshConvRings : torch::CustomClassHolder {
  RingRows matrix, adjoint;
};

// Eq. 2 on [B, V, C] inputs: y_i = W1 x_i + W2 mean_{j in N(i)} x_j + b.
// The transpose spreads instead of gathering: y_j = W1 x_j + W2 sum_{i: j in
// N(i)} x_i / d_i + b (the adjoint of the neighbour mean).
class MeshConvImpl : public torch::nn::Module {
 public:
  MeshConvImpl(int in, int out, MeshGraph graph, bool transpose);
  torch::Tensor forward(const torch::Tensor& x);
  // The same on [V, B, C] (vertices first, contiguous), by libtorch's ops.
  torch::Tensor forward_vertices_first(const torch::Tensor& x);
  // The same on [V, C, B] (the batch innermost), then tanh when `squash`,
  // as one autograd node of hand-written loops (mesh_conv_kernel.hpp), as
  // the network runs it.
  torch::Tensor forward_fused(const torch::Tensor& x, bool squash);
  // The neighbour mean (or its adjoint) alone, on [B, V, C] and on [V, B, C].
  torch::Tensor ring(const torch::Tensor& x) const;
  torch::Tensor ring_vertices_first(const torch::Tensor& x) const;

  torch::nn::Linear self{nullptr};
  torch::nn::Linear neighbours{nullptr};

 private:
  MeshGraph graph_;
  bool transpose_;
  torch::Tensor matrix_, adjoint_;           // sparse V x V: the product and its adjoint
  c10::intrusive_ptr<MeshConvRings> rings_;  // the same by rows, for forward_fused
};
TORCH_MODULE(MeshConv);

using LstmState = std::tuple<torch::Tensor, torch::Tensor>;  // h, c: [layers, B, hidden]

struct Chain {
  torch::Tensor frames;  // [n, B, D]: the given frames, then the generated ones
  torch::Tensor mu;      // [n - 1, B, latent]
  torch::Tensor logvar;  // [n - 1, B, latent]
};

class SeqNetImpl : public torch::nn::Module {
 public:
  SeqNetImpl(const NetShape& shape, MeshGraph graph);

  const NetShape& shape() const { return shape_; }
  // [B, D] -> mean and log-variance [B, latent].
  std::pair<torch::Tensor, torch::Tensor> encode(const torch::Tensor& x);
  // [B, D] -> the encoder's output, flattened [B, V C] (or [B, width]).
  torch::Tensor encoded(const torch::Tensor& x);
  // [B, hidden] -> feature change [B, D].
  torch::Tensor decode(const torch::Tensor& h);
  // The same from the decoder's first dense layer's output (before tanh).
  torch::Tensor decode_from(const torch::Tensor& dense);
  // A mesh model's encoder output with the batch innermost, [V C, B], and
  // the decoder from the dense layer's output so laid out, [V C, B] ->
  // [B, D]: what the training step's dense products take and give.
  torch::Tensor encoded_batch_inner(const torch::Tensor& x);
  torch::Tensor decode_batch_inner(const torch::Tensor& dense);
  // Every state entry sign * s0 (sign +1 forward, -1 backward).
  LstmState initial_state(int batch, double sign) const;
  // Runs the chain from `given` ([u, B, D], u >= 1) to n frames: the given
  // frames are fed in order, then each output is the next input. With
  // `sample` the latent is drawn (training), else its mean is used.
  Chain run(const torch::Tensor& given, int n, LstmState state, bool sample);

  // While on, the chains' dense layers (mean and log-variance, the
  // decoder's first layer) leave their weight gradients out of autograd and
  // keep each step's input and output gradient instead; after backward,
  // finish_gradients forms each weight's gradient in one product over all
  // steps (the same sum as autograd's, without one full-size matrix per step).
  // Sets the decoder's last layer to zero, weights and bias: every frame's
  // change is zero until training moves it, so an untrained network holds
  // its given frame and completes a gap as linear interpolation of the keys
  // (CompletionOptions::blend). The layer's weight gradients are not zero
  // (its input is not), so it learns from the first step.
  void zero_output_layer();

  void collect_dense_gradients(bool on);
  void finish_gradients();

  torch::nn::Sequential encoder{nullptr};  // mesh convolutions or dense layers, tanh
  torch::nn::Linear to_mu{nullptr};
  torch::nn::Linear to_logvar{nullptr};
  torch::nn::LSTM lstm{nullptr};
  torch::nn::Linear from_hidden{nullptr};
  torch::nn::Sequential decoder{nullptr};  // transpose convolutions or dense layers

 private:
  NetShape shape_;
  std::shared_ptr<struct DenseTapes> tapes_;
};
TORCH_MODULE(SeqNet);

// Loss terms (docs/seqnet.md, "Losses"). S^f, S^b and X are [n, B, D]; a
// frame's distance is the mean squared difference over its B x D entries.
// `weight` [D] (optional) weighs each number of a frame in its distance.
// sum_i |S^f_i - X_i| + |S^b_i - X_{n+1-i}|
torch::Tensor recon_loss(const torch::Tensor& forward, const torch::Tensor& backward,
                         const torch::Tensor& truth, const torch::Tensor& weight = {});
// sum_i |S^f_i - S^b_{n+1-i}|
torch::Tensor bidir_loss(const torch::Tensor& forward, const torch::Tensor& backward,
                         const torch::Tensor& weight = {});
// Both at once on the frames of both chains run as one batch, [n, 2 B, D]
// (the forward chain's B sequences first): {recon, bidir}, one autograd
// node; `weight` as above.
std::pair<torch::Tensor, torch::Tensor> chain_losses(const torch::Tensor& frames,
                                                     const torch::Tensor& truth,
                                                     const torch::Tensor& weight = {});
// Weights of a frame's D numbers: `placement_weight` for the last
// `placement_values` (the placement nodes: where the body goes and where
// the other pieces sit), 1 for the rest; undefined (no weighting) when all
// are 1. Throws std::invalid_argument for a weight that is not positive
// and finite.
torch::Tensor frame_weights(int dims, int placement_values, double placement_weight);
// KL(N(mu, exp(logvar)) || N(0, 1)), mean over all latent entries.
torch::Tensor kl_loss(const torch::Tensor& mu, const torch::Tensor& logvar);
// Mean square of the weights (matrices, not biases) of the module.
torch::Tensor l2_loss(const torch::nn::Module& net);
// Adds `scale` times l2_loss's gradient to each weight's gradient (what
// backward through scale * l2_loss would add).
void add_l2_gradient(const torch::nn::Module& net, double scale);

struct LossTerms {
  torch::Tensor recon, bidir, kl, l2, total;
  // The L2 norm of all gradients together before any clipping (train_step
  // with clipping on; 0 otherwise).
  double gradient_norm = 0;
};
// L_recon + 0.5 L_bidir + 0.1 (L_KL + L2) for one batch of ground-truth
// windows X [n, B, D]: the forward chain from X_1 with +s0, the backward
// chain from X_n with -s0. `kl_weight`, `l2_weight` and `bidirectional`
// switch terms off for ablations (1, 1 and true: the paper); `frame_weight`
// (frame_weights) weighs the frame distances of L_recon and L_bidir.
LossTerms batch_loss(SeqNet& net, const torch::Tensor& truth, bool sample, double kl_weight = 1.0,
                     bool bidirectional = true, double l2_weight = 1.0,
                     const torch::Tensor& frame_weight = {});

class Adam;

// One training iteration on the windows X [n, B, D]: batch_loss with
// latent sampling, its gradients, one Adam step. Returns the loss terms.
// `clip_gradient` > 0 scales all gradients together down to that L2 norm
// when they are longer (Adam::clip), so one unusual batch cannot throw the
// weights far; 0 leaves them as they are.
LossTerms train_step(SeqNet& net, Adam& adam, const torch::Tensor& truth, double kl_weight = 1.0,
                     bool bidirectional = true, double l2_weight = 1.0,
                     const torch::Tensor& frame_weight = {}, double clip_gradient = 0);

// Adam (beta 0.9, 0.999, eps 1e-8) over the net's parameters, with state
// that a checkpoint saves and restores exactly.
class Adam {
 public:
  Adam(std::vector<torch::Tensor> parameters, double learning_rate);
  void step();  // uses each parameter's grad; then zeroes the grads
  // The L2 norm of all parameters' gradients together; when it is above
  // `max_norm` every gradient is scaled by max_norm / norm. Returns the
  // norm before scaling.
  double clip(double max_norm);
  std::int64_t steps() const { return steps_; }
  std::vector<NamedArray> state(const std::vector<std::string>& names) const;
  // Throws InputError (naming `file`) when the state does not fit.
  void restore(const std::vector<NamedArray>& state, const std::vector<std::string>& names,
               const std::string& file);

 private:
  std::vector<torch::Tensor> params_, m_, v_;
  double lr_;
  std::int64_t steps_ = 0;
};

// Parameters as named arrays (model file) and back. load_parameters throws
// InputError naming the file and the parameter that is missing or of
// another shape.
std::vector<NamedArray> save_parameters(const SeqNetImpl& net);
void load_parameters(SeqNetImpl& net, const std::vector<NamedArray>& arrays,
                     const std::string& file);

// A network for a model file (its shape and mesh), parameters loaded.
SeqNet network_for(const ModelFile& model, const std::string& file);

}  // namespace animrt::seqnet
