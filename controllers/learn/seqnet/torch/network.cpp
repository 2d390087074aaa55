#include "animrt/learn/seqnet/network.hpp"

#include <ATen/Parallel.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>

#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/dense_kernel.hpp"
#include "animrt/learn/seqnet/lstm_kernel.hpp"
#include "animrt/learn/seqnet/lstm_step.hpp"
#include "animrt/learn/seqnet/mesh_conv_kernel.hpp"
#include "animrt/learn/seqnet/train_kernel.hpp"

namespace animrt::seqnet {

MeshGraph mesh_graph(int vertex_count, const std::vector<std::array<int, 3>>& triangles) {
  std::vector<std::set<int>> ring(static_cast<std::size_t>(vertex_count));
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[static_cast<std::size_t>(k)];
      const int b = t[static_cast<std::size_t>((k + 1) % 3)];
      ring[static_cast<std::size_t>(a)].insert(b);
      ring[static_cast<std::size_t>(b)].insert(a);
    }
  }
  std::vector<std::int64_t> rows, cols;
  std::vector<float> weights;
  for (int i = 0; i < vertex_count; ++i) {
    const auto& r = ring[static_cast<std::size_t>(i)];
    for (int j : r) {
      rows.push_back(i);
      cols.push_back(j);
      weights.push_back(1.0F / static_cast<float>(r.size()));
    }
  }
  const auto n = static_cast<std::int64_t>(rows.size());
  MeshGraph g;
  g.vertex_count = vertex_count;
  g.rows = torch::from_blob(rows.data(), {n}, torch::kInt64).clone();
  g.cols = torch::from_blob(cols.data(), {n}, torch::kInt64).clone();
  g.weights = torch::from_blob(weights.data(), {n}, torch::kFloat32).clone();
  return g;
}

namespace {

// The ring mean as an autograd function: a sparse product forward, the
// product with the precomputed adjoint backward (libtorch would transpose
// and sort the sparse matrix again at every step).
struct RingProduct : torch::autograd::Function<RingProduct> {
  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& columns,
                               const torch::Tensor& matrix, const torch::Tensor& adjoint) {
    ctx->saved_data["adjoint"] = adjoint;
    return torch::mm(matrix, columns);
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grad) {
    return {torch::mm(ctx->saved_data["adjoint"].toTensor(), grad[0]), torch::Tensor(),
            torch::Tensor()};
  }
};

// tanh in place as 2 sigmoid(2 y) - 1 in one pass (lstm_kernel.hpp):
// libtorch's tanh took four times as long, its sigmoid four passes.
torch::Tensor& squash_(torch::Tensor& y) {
  TORCH_CHECK(y.is_contiguous() && y.scalar_type() == torch::kFloat32, "tanh: contiguous float");
  tanh_in_place(y.data_ptr<float>(), static_cast<std::size_t>(y.numel()));
  return y;
}

// tanh by squash_, as an autograd node (backward: tanh's, from the output).
struct Squash : torch::autograd::Function<Squash> {
  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& x) {
    torch::Tensor y = x.clone(at::MemoryFormat::Contiguous);
    squash_(y);
    ctx->save_for_backward({y});
    return y;
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grad) {
    return {torch::tanh_backward(grad[0], ctx->get_saved_variables()[0])};
  }
};

// One mesh convolution on [V, C, B] (batch innermost), its tanh included
// when `squash`, as one autograd node: y = act(W1 x + W2 (M x) + b) per
// vertex, by the loops of mesh_conv_kernel.hpp over ranges of vertices
// (split between libtorch's threads). Backward forms the gradients of x,
// both weights and the bias in two passes over the vertices.
struct FusedMeshConv : torch::autograd::Function<FusedMeshConv> {
  static constexpr std::int64_t grain = 64;  // vertices a thread takes at least

  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& x,
                               const torch::Tensor& w_self, const torch::Tensor& bias,
                               const torch::Tensor& w_ring,
                               const c10::intrusive_ptr<MeshConvRings>& rings, bool squash) {
    TORCH_CHECK(x.dim() == 3 && x.scalar_type() == torch::kFloat32 && x.is_contiguous(),
                "mesh convolution: x must be a contiguous float [V, C, B]");
    const ConvShape s{static_cast<int>(x.size(0)), static_cast<int>(x.size(1)),
                      static_cast<int>(w_self.size(0)), static_cast<int>(x.size(2))};
    TORCH_CHECK(s.vertices == rings->matrix.vertices && s.in == w_self.size(1),
                "mesh convolution: x does not fit the mesh or the weights");
    const torch::Tensor ws = w_self.contiguous(), wr = w_ring.contiguous(), b = bias.contiguous();
    torch::Tensor ring = torch::empty_like(x);
    torch::Tensor y = torch::empty({s.vertices, s.out, s.batch}, x.options());
    at::parallel_for(0, s.vertices, grain, [&](std::int64_t first, std::int64_t last) {
      mesh_conv_forward(s, rings->matrix, x.data_ptr<float>(), ws.data_ptr<float>(),
                        wr.data_ptr<float>(), b.data_ptr<float>(), ring.data_ptr<float>(),
                        y.data_ptr<float>(), static_cast<int>(first), static_cast<int>(last));
    });
    if (squash) squash_(y);
    ctx->save_for_backward({x, ring, y, ws, wr});
    ctx->saved_data["rings"] = c10::IValue::make_capsule(rings);
    ctx->saved_data["squash"] = squash;
    return y;
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grad) {
    const auto saved = ctx->get_saved_variables();
    const torch::Tensor &x = saved[0], &ring = saved[1], &y = saved[2];
    const torch::Tensor &w_self = saved[3], &w_ring = saved[4];
    const auto rings =
        c10::static_intrusive_pointer_cast<MeshConvRings>(ctx->saved_data["rings"].toCapsule());
    const bool squash = ctx->saved_data["squash"].toBool();
    const ConvShape s{static_cast<int>(x.size(0)), static_cast<int>(x.size(1)),
                      static_cast<int>(w_self.size(0)), static_cast<int>(x.size(2))};
    const torch::Tensor g = grad[0].contiguous();
    torch::Tensor gx = torch::empty_like(x), through = torch::empty_like(x);
    // One set of weight-gradient sums per thread ([W1 | W2 | b], each
    // number kConvLanes wide), added up after in a plain loop: as libtorch
    // tensors they were six more operations per node.
    const auto threads = static_cast<std::size_t>(at::get_num_threads());
    const auto weights = static_cast<std::size_t>(s.out) * static_cast<std::size_t>(s.in);
    const std::size_t numbers = 2 * weights + static_cast<std::size_t>(s.out);
    std::vector<float> acc(threads * numbers * kConvLanes, 0.0F);
    at::parallel_for(0, s.vertices, grain, [&](std::int64_t first, std::int64_t last) {
      float* a = acc.data() + static_cast<std::size_t>(at::get_thread_num()) * numbers * kConvLanes;
      mesh_conv_backward_local(
          s, x.data_ptr<float>(), ring.data_ptr<float>(), squash ? y.data_ptr<float>() : nullptr,
          g.data_ptr<float>(), w_self.data_ptr<float>(), w_ring.data_ptr<float>(),
          gx.data_ptr<float>(), through.data_ptr<float>(), a, a + weights * kConvLanes,
          a + 2 * weights * kConvLanes, static_cast<int>(first), static_cast<int>(last));
    });
    at::parallel_for(0, s.vertices, grain, [&](std::int64_t first, std::int64_t last) {
      mesh_conv_backward_ring(s, rings->adjoint, through.data_ptr<float>(), gx.data_ptr<float>(),
                              static_cast<int>(first), static_cast<int>(last));
    });
    // Each gradient its own tensor (autograd may keep it as the .grad).
    torch::Tensor g_self = torch::empty({s.out, s.in}, x.options());
    torch::Tensor g_ring = torch::empty({s.out, s.in}, x.options());
    torch::Tensor g_bias = torch::empty({s.out}, x.options());
    // Number k of [W1 | W2 | b] summed over threads and lanes.
    const auto sum = [&](std::size_t k) {
      float total = 0.0F;
      for (std::size_t t = 0; t < threads; ++t) {
        const float* lanes = acc.data() + (t * numbers + k) * kConvLanes;
        for (int j = 0; j < kConvLanes; ++j) total += lanes[j];
      }
      return total;
    };
    for (std::size_t k = 0; k < weights; ++k) {
      g_self.data_ptr<float>()[k] = sum(k);
      g_ring.data_ptr<float>()[k] = sum(weights + k);
    }
    for (std::size_t k = 0; k < static_cast<std::size_t>(s.out); ++k) {
      g_bias.data_ptr<float>()[k] = sum(2 * weights + k);
    }
    return {gx, g_self, g_bias, g_ring, torch::Tensor(), torch::Tensor()};
  }
};

// The V x V matrix with `weights` at (rows, cols), coalesced.
torch::Tensor ring_matrix(const torch::Tensor& rows, const torch::Tensor& cols,
                          const torch::Tensor& weights, std::int64_t v) {
  return torch::sparse_coo_tensor(torch::stack({rows, cols}), weights, {v, v}).coalesce();
}

}  // namespace

MeshConvImpl::MeshConvImpl(int in, int out, MeshGraph graph, bool transpose)
    : graph_(std::move(graph)), transpose_(transpose) {
  self = register_module("self", torch::nn::Linear(torch::nn::LinearOptions(in, out)));
  neighbours = register_module("neighbours",
                               torch::nn::Linear(torch::nn::LinearOptions(in, out).bias(false)));
  // The neighbour mean (row i: 1/d_i at its neighbours) and its adjoint,
  // built once; a transpose convolution multiplies by the adjoint.
  const std::int64_t v = graph_.vertex_count;
  if (v > 0) {
    torch::Tensor mean = ring_matrix(graph_.rows, graph_.cols, graph_.weights, v);
    torch::Tensor adjoint = ring_matrix(graph_.cols, graph_.rows, graph_.weights, v);
    matrix_ = transpose_ ? adjoint : mean;
    adjoint_ = transpose_ ? mean : adjoint;
  }
  const auto list = [](const torch::Tensor& t, auto element) {
    using T = decltype(element);
    const torch::Tensor c = t.contiguous();
    return std::vector<T>(c.data_ptr<T>(), c.data_ptr<T>() + c.numel());
  };
  const auto rows = list(graph_.rows, std::int64_t{}), cols = list(graph_.cols, std::int64_t{});
  const auto weights = list(graph_.weights, 0.0F);
  RingRows mean_rows = ring_rows(static_cast<int>(v), rows, cols, weights);
  RingRows adjoint_rows = ring_rows(static_cast<int>(v), cols, rows, weights);
  rings_ = c10::make_intrusive<MeshConvRings>();
  rings_->matrix = transpose_ ? std::move(adjoint_rows) : std::move(mean_rows);
  rings_->adjoint = transpose_ ? std::move(mean_rows) : std::move(adjoint_rows);
}

torch::Tensor MeshConvImpl::ring_vertices_first(const torch::Tensor& x) const {
  const std::int64_t v = x.size(0);
  const torch::Tensor columns = x.reshape({v, -1});
  return RingProduct::apply(columns, matrix_, adjoint_).view(x.sizes());
}

torch::Tensor MeshConvImpl::ring(const torch::Tensor& x) const {
  return ring_vertices_first(x.transpose(0, 1).contiguous()).transpose(0, 1);
}

torch::Tensor MeshConvImpl::forward(const torch::Tensor& x) {
  return forward_vertices_first(x.transpose(0, 1).contiguous()).transpose(0, 1);
}

torch::Tensor MeshConvImpl::forward_fused(const torch::Tensor& x, bool squash) {
  return FusedMeshConv::apply(x.contiguous(), self->weight, self->bias, neighbours->weight, rings_,
                              squash);
}

torch::Tensor MeshConvImpl::forward_vertices_first(const torch::Tensor& x) {
  // [V, B, C] rows are vertex-major, so the ring product needs no copy and
  // both weight matrices act on [V B, C] in one product each.
  const std::int64_t v = x.size(0), batch = x.size(1), c = x.size(2);
  const torch::Tensor flat = x.reshape({v * batch, c});
  const torch::Tensor r = ring_vertices_first(x).view({v * batch, c});
  const torch::Tensor y = torch::addmm(self->bias, flat, self->weight.t());
  return torch::addmm(y, r, neighbours->weight.t()).view({v, batch, -1});
}

SeqNetImpl::SeqNetImpl(const NetShape& shape, MeshGraph graph) : shape_(shape) {
  const bool mesh = shape.kind == ModelKind::mesh;
  // Placement nodes follow the vertices with no neighbours: the ring
  // products leave them out, the dense layers mix them in.
  if (mesh) graph.vertex_count = shape.nodes();
  const int width = mesh ? shape.channels : shape.dense_width;
  encoder = torch::nn::Sequential();
  decoder = torch::nn::Sequential();
  for (int k = 0; k < shape.conv_layers; ++k) {
    if (mesh) {
      encoder->push_back(MeshConv(k == 0 ? 9 : width, width, graph, false));
    } else {
      encoder->push_back(torch::nn::Linear(k == 0 ? shape.joint_count : width, width));
    }
    encoder->push_back(torch::nn::Tanh());
  }
  const std::int64_t flat = mesh ? std::int64_t{shape.nodes()} * width : width;
  encoder = register_module("encoder", encoder);
  to_mu = register_module("to_mu", torch::nn::Linear(flat, shape.latent));
  to_logvar = register_module("to_logvar", torch::nn::Linear(flat, shape.latent));
  lstm = register_module(
      "lstm",
      torch::nn::LSTM(
          torch::nn::LSTMOptions(shape.latent, shape.hidden).num_layers(shape.lstm_layers)));
  from_hidden = register_module("from_hidden", torch::nn::Linear(shape.hidden, flat));
  for (int k = 0; k < shape.conv_layers; ++k) {
    const bool last = k + 1 == shape.conv_layers;
    const int out = last ? (mesh ? 9 : shape.joint_count) : width;
    if (mesh) {
      decoder->push_back(MeshConv(width, out, graph, true));
    } else {
      decoder->push_back(torch::nn::Linear(width, out));
    }
    if (!last) decoder->push_back(torch::nn::Tanh());
  }
  decoder = register_module("decoder", decoder);
}

void SeqNetImpl::zero_output_layer() {
  torch::NoGradGuard no_grad;
  for (auto& p : decoder->children().back()->parameters()) p.zero_();
}

namespace {

// A Sequential of mesh convolutions and tanh on [V, C, B]; a convolution
// and the tanh after it run as one node.
torch::Tensor run_vertices_first(torch::nn::Sequential& layers, torch::Tensor h) {
  const auto children = layers->children();
  for (std::size_t k = 0; k < children.size(); ++k) {
    if (auto* conv = children[k]->as<MeshConvImpl>()) {
      const bool squash =
          k + 1 < children.size() && children[k + 1]->as<torch::nn::TanhImpl>() != nullptr;
      h = conv->forward_fused(h, squash);
      if (squash) ++k;
    } else {
      h = torch::tanh(h);
    }
  }
  return h;
}

}  // namespace

torch::Tensor SeqNetImpl::encoded(const torch::Tensor& x) {
  const std::int64_t batch = x.size(0);
  if (shape_.kind != ModelKind::mesh) return encoder->forward(x);
  // Back to [B, V C] for the dense layers.
  return encoded_batch_inner(x).view({shape_.nodes(), -1, batch}).permute({2, 0, 1}).reshape(
      {batch, -1});
}

torch::Tensor SeqNetImpl::encoded_batch_inner(const torch::Tensor& x) {
  // [V, C, B] through the convolutions.
  const std::int64_t batch = x.size(0);
  torch::Tensor h = x.view({batch, shape_.nodes(), 9}).permute({1, 2, 0}).contiguous();
  return run_vertices_first(encoder, h).view({-1, batch});
}

std::pair<torch::Tensor, torch::Tensor> SeqNetImpl::encode(const torch::Tensor& x) {
  const torch::Tensor h = encoded(x);
  return {to_mu->forward(h), to_logvar->forward(h)};
}

torch::Tensor SeqNetImpl::decode(const torch::Tensor& hidden) {
  return decode_from(from_hidden->forward(hidden));
}

torch::Tensor SeqNetImpl::decode_from(const torch::Tensor& dense) {
  if (shape_.kind != ModelKind::mesh) return decoder->forward(torch::tanh(dense));
  return decode_batch_inner(dense.t().contiguous());  // the squash is per element
}

torch::Tensor SeqNetImpl::decode_batch_inner(const torch::Tensor& dense) {
  const std::int64_t batch = dense.size(1);
  const torch::Tensor h = Squash::apply(dense).view({shape_.nodes(), shape_.channels, batch});
  return run_vertices_first(decoder, h).permute({2, 0, 1}).reshape({batch, -1});
}

void dense_batch_inner_threads(const float* packed, const float* bias, const float* x, int rows,
                               int cols, int batch, float* y) {
  constexpr std::int64_t kGrain = 4;  // blocks of output rows a thread takes at least
  const auto blocks = (rows + kDenseRows - 1) / kDenseRows;
  at::parallel_for(0, blocks, kGrain, [&](std::int64_t first, std::int64_t last) {
    dense_batch_inner(packed, bias, x, rows, cols, batch, y, static_cast<int>(first),
                      static_cast<int>(last));
  });
}

namespace {

// A dense layer's weight W (out x in) packed for dense_kernel.hpp's
// products: W for forward, W^T for the input's gradient.
struct DensePack : torch::CustomClassHolder {
  int out = 0, in = 0;
  std::vector<float> forward, backward;
};

c10::intrusive_ptr<DensePack> pack_dense(const torch::Tensor& weight) {
  const torch::Tensor w = weight.detach().contiguous();
  auto p = c10::make_intrusive<DensePack>();
  p->out = static_cast<int>(w.size(0));
  p->in = static_cast<int>(w.size(1));
  p->forward.resize(dense_packed_size(p->out, p->in));
  p->backward.resize(dense_packed_size(p->in, p->out));
  pack_dense_rows(w.data_ptr<float>(), p->out, p->in, p->in, 1, p->forward.data());
  pack_dense_rows(w.data_ptr<float>(), p->in, p->out, 1, p->in, p->backward.data());
  return p;
}


// y = W x + b on x [in, B] (the batch innermost) to y [out, B], with W and
// b outside autograd (their gradients are the tape's); x's gradient W^T g.
struct BatchInnerDense : torch::autograd::Function<BatchInnerDense> {
  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& x,
                               const torch::Tensor& bias, const c10::intrusive_ptr<DensePack>& w) {
    TORCH_CHECK(x.dim() == 2 && x.size(0) == w->in && x.scalar_type() == torch::kFloat32,
                "dense layer: x must be float [in, B]");
    const torch::Tensor xc = x.contiguous(), b = bias.detach().contiguous();
    const auto batch = static_cast<int>(x.size(1));
    torch::Tensor y = torch::empty({w->out, batch}, x.options());
    dense_batch_inner_threads(w->forward.data(), b.data_ptr<float>(), xc.data_ptr<float>(), w->out,
                              w->in, batch, y.data_ptr<float>());
    ctx->saved_data["w"] = c10::IValue::make_capsule(w);
    return y;
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grad) {
    const auto w = c10::static_intrusive_pointer_cast<DensePack>(ctx->saved_data["w"].toCapsule());
    const torch::Tensor g = grad[0].contiguous();
    const auto batch = static_cast<int>(g.size(1));
    torch::Tensor gx = torch::empty({w->in, batch}, g.options());
    dense_batch_inner_threads(w->backward.data(), nullptr, g.data_ptr<float>(), w->in, w->out,
                              batch, gx.data_ptr<float>());
    return {gx, torch::Tensor(), torch::Tensor()};
  }
};

}  // namespace

// Inputs and output gradients of one dense layer over the steps of a run.
struct DenseTape {
  std::vector<torch::Tensor> inputs, grads;

  // y = x W^T + b with W and b outside autograd; x's gradient still flows.
  torch::Tensor apply(const std::shared_ptr<DenseTape>& self, const torch::Tensor& x,
                      const torch::Tensor& weight, const torch::Tensor& bias) {
    torch::Tensor y = torch::addmm(bias.detach(), x, weight.detach().t());
    const std::size_t slot = inputs.size();
    inputs.push_back(x.detach());
    grads.emplace_back();
    std::weak_ptr<DenseTape> tape = self;
    y.register_hook([tape, slot](const torch::Tensor& g) {
      if (auto t = tape.lock()) t->grads[slot] = g;
    });
    return y;
  }

  // The same on x [in, B] to [out, B] (the batch innermost), W packed.
  torch::Tensor apply_batch_inner(const std::shared_ptr<DenseTape>& self, const torch::Tensor& x,
                                  const c10::intrusive_ptr<DensePack>& weight,
                                  const torch::Tensor& bias) {
    torch::Tensor y = BatchInnerDense::apply(x, bias, weight);
    const std::size_t slot = inputs.size();
    inputs.push_back(x.detach().t());
    grads.emplace_back();
    std::weak_ptr<DenseTape> tape = self;
    y.register_hook([tape, slot](const torch::Tensor& g) {
      if (auto t = tape.lock()) t->grads[slot] = g.t();
    });
    return y;
  }

  // sum_t g_t^T x_t and sum_t g_t over the steps that got a gradient.
  std::pair<torch::Tensor, torch::Tensor> gradients() const {
    std::vector<torch::Tensor> x, g;
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      if (!grads[k].defined()) continue;
      x.push_back(inputs[k]);
      g.push_back(grads[k]);
    }
    if (g.empty()) return {};
    const torch::Tensor gs = torch::cat(g), xs = torch::cat(x);
    return {torch::mm(gs.t(), xs), gs.sum(0)};
  }
};

struct DenseTapes {
  bool on = false;
  std::vector<std::shared_ptr<DenseTape>> latent, hidden;  // one per run
  std::vector<c10::intrusive_ptr<LstmPack>> lstm;            // one per run
};

namespace {

void add_gradient(torch::Tensor& parameter, const torch::Tensor& g) {
  if (parameter.grad().defined()) {
    parameter.mutable_grad().add_(g);
  } else {
    parameter.mutable_grad() = g.clone();
  }
}

}  // namespace

void SeqNetImpl::collect_dense_gradients(bool on) {
  if (!tapes_) tapes_ = std::make_shared<DenseTapes>();
  tapes_->on = on;
}

void SeqNetImpl::finish_gradients() {
  if (!tapes_) return;
  torch::NoGradGuard no_grad;
  const std::int64_t latent = shape_.latent;
  for (const auto& tape : tapes_->latent) {
    auto [w, b] = tape->gradients();
    if (!w.defined()) continue;
    add_gradient(to_mu->weight, w.slice(0, 0, latent));
    add_gradient(to_logvar->weight, w.slice(0, latent));
    add_gradient(to_mu->bias, b.slice(0, 0, latent));
    add_gradient(to_logvar->bias, b.slice(0, latent));
  }
  for (const auto& tape : tapes_->hidden) {
    auto [w, b] = tape->gradients();
    if (!w.defined()) continue;
    add_gradient(from_hidden->weight, w);
    add_gradient(from_hidden->bias, b);
  }
  auto lstm_params = lstm->named_parameters();
  for (const auto& pack : tapes_->lstm) {
    for (const auto& [name, g] : lstm_gradients(*pack)) add_gradient(lstm_params[name], g);
  }
  tapes_->latent.clear();
  tapes_->hidden.clear();
  tapes_->lstm.clear();
}

LstmState SeqNetImpl::initial_state(int batch, double sign) const {
  const auto value = sign * shape_.s0;
  return {torch::full({shape_.lstm_layers, batch, shape_.hidden}, value),
          torch::full({shape_.lstm_layers, batch, shape_.hidden}, value)};
}

Chain SeqNetImpl::run(const torch::Tensor& given, int n, LstmState state, bool sample) {
  const std::int64_t u = given.size(0);
  std::vector<torch::Tensor> frames{given[0]}, mus, logvars;
  torch::Tensor x = given[0];
  // Mean and log-variance in one product per step (the same numbers as
  // two): the weights are stacked once per chain.
  const bool tape = tapes_ && tapes_->on && torch::GradMode::is_enabled();
  std::shared_ptr<DenseTape> latent_tape, hidden_tape;
  if (tape) {
    latent_tape = tapes_->latent.emplace_back(std::make_shared<DenseTape>());
    hidden_tape = tapes_->hidden.emplace_back(std::make_shared<DenseTape>());
  }
  const torch::Tensor weight = torch::cat({to_mu->weight, to_logvar->weight});
  const torch::Tensor bias = torch::cat({to_mu->bias, to_logvar->bias});
  // A mesh model's taped steps run the dense layers on the batch-innermost
  // activations of the convolutions, by the loops of dense_kernel.hpp.
  const bool inner = tape && shape_.kind == ModelKind::mesh;
  c10::intrusive_ptr<DensePack> latent_pack, hidden_pack;
  // Taped steps run the LSTM as one node per step (lstm_step.hpp), on
  // states with the batch innermost.
  c10::intrusive_ptr<LstmPack> lstm_pack;
  if (tape) {
    lstm_pack = tapes_->lstm.emplace_back(pack_lstm(*lstm));
    state = {std::get<0>(state).transpose(1, 2).contiguous(),
             std::get<1>(state).transpose(1, 2).contiguous()};
  }
  if (inner) {
    latent_pack = pack_dense(weight);
    hidden_pack = pack_dense(from_hidden->weight);
  }
  for (int t = 1; t < n; ++t) {
    torch::Tensor latent_out;
    if (inner) {
      latent_out =
          latent_tape->apply_batch_inner(latent_tape, encoded_batch_inner(x), latent_pack, bias)
              .t()
              .contiguous();
    } else {
      const torch::Tensor h = encoded(x);
      latent_out =
          tape ? latent_tape->apply(latent_tape, h, weight, bias) : torch::addmm(bias, h, weight.t());
    }
    const std::vector<torch::Tensor> latent = latent_out.chunk(2, 1);
    const torch::Tensor& mu = latent[0];
    const torch::Tensor& logvar = latent[1];
    torch::Tensor z = mu;
    if (sample) z = mu + torch::randn_like(mu) * torch::exp(0.5 * logvar);
    torch::Tensor o, o_inner;  // [B, hidden], and [hidden, B] from the fused step
    if (lstm_pack) {
      auto [h, c] = lstm_step(z, std::get<0>(state), std::get<1>(state), lstm_pack);
      o_inner = h[shape_.lstm_layers - 1];
      o = o_inner.t();
      state = {h, c};
    } else {
      auto [out, next_state] = lstm->forward(z.unsqueeze(0), state);
      state = next_state;
      o = out.squeeze(0);
    }
    torch::Tensor change;
    if (inner) {
      change = decode_batch_inner(
          hidden_tape->apply_batch_inner(hidden_tape, o_inner, hidden_pack, from_hidden->bias));
    } else if (tape) {
      change = decode_from(
          hidden_tape->apply(hidden_tape, o, from_hidden->weight, from_hidden->bias));
    } else {
      change = decode(o);
    }
    const torch::Tensor generated = x + change;
    x = t < u ? given[t] : generated;
    frames.push_back(x);
    mus.push_back(mu);
    logvars.push_back(logvar);
  }
  return {torch::stack(frames), torch::stack(mus), torch::stack(logvars)};
}

namespace {
// Per frame, the mean over its B x D entries of the (weighted) squares.
torch::Tensor frame_distances(const torch::Tensor& difference, const torch::Tensor& weight) {
  const torch::Tensor squares = difference.pow(2);
  return (weight.defined() ? squares * weight : squares).flatten(1).mean(1);
}
}  // namespace

torch::Tensor recon_loss(const torch::Tensor& forward, const torch::Tensor& backward,
                         const torch::Tensor& truth, const torch::Tensor& weight) {
  const torch::Tensor f = frame_distances(forward - truth, weight);
  const torch::Tensor b = frame_distances(backward - truth.flip(0), weight);
  return (f + b).sum();
}

torch::Tensor bidir_loss(const torch::Tensor& forward, const torch::Tensor& backward,
                         const torch::Tensor& weight) {
  return frame_distances(forward - backward.flip(0), weight).sum();
}

torch::Tensor frame_weights(int dims, int placement_values, double placement_weight) {
  if (!(placement_weight > 0) || !std::isfinite(placement_weight)) {
    throw std::invalid_argument("placement weight " + std::to_string(placement_weight) +
                                ": must be a positive number");
  }
  if (placement_values < 0 || placement_values > dims) {
    throw std::invalid_argument("placement values " + std::to_string(placement_values) +
                                " of a frame of " + std::to_string(dims));
  }
  if (placement_weight == 1.0 || placement_values == 0) return {};
  torch::Tensor w = torch::ones({dims});
  w.slice(0, dims - placement_values, dims).fill_(placement_weight);
  return w;
}

namespace {

// recon_loss and bidir_loss of the two chains as one autograd node over
// the frames of both [n, 2 B, D] (train_kernel.hpp): one pass forward, one
// backward, where libtorch's slices, flips, differences, squares and means
// each took a pass over the frames, forward and backward.
struct ChainLosses : torch::autograd::Function<ChainLosses> {
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx,
                                                const torch::Tensor& frames,
                                                const torch::Tensor& truth,
                                                const torch::Tensor& weight) {
    TORCH_CHECK(frames.dim() == 3 && truth.dim() == 3 && frames.size(0) == truth.size(0) &&
                    frames.size(1) == 2 * truth.size(1) && frames.size(2) == truth.size(2) &&
                    frames.scalar_type() == torch::kFloat32 &&
                    truth.scalar_type() == torch::kFloat32,
                "chain losses: frames [n, 2B, D] and truth [n, B, D], float");
    TORCH_CHECK(weight.numel() == 0 || (weight.dim() == 1 && weight.size(0) == truth.size(2) &&
                                        weight.scalar_type() == torch::kFloat32),
                "chain losses: weight [D], float, or none");
    const torch::Tensor f = frames.contiguous(), x = truth.contiguous(), w = weight.contiguous();
    double recon = 0.0, bidir = 0.0;
    chain_loss_sums(f.data_ptr<float>(), x.data_ptr<float>(), weight_data(w),
                    static_cast<int>(x.size(0)), static_cast<int>(x.size(1)),
                    static_cast<int>(x.size(2)), &recon, &bidir);
    ctx->save_for_backward({f, x, w});
    return {torch::tensor(static_cast<float>(recon)), torch::tensor(static_cast<float>(bidir))};
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grad) {
    const auto saved = ctx->get_saved_variables();
    const torch::Tensor &f = saved[0], &x = saved[1], &w = saved[2];
    const auto scalar = [](const torch::Tensor& g) { return g.defined() ? g.item<float>() : 0.0F; };
    torch::Tensor df = torch::empty_like(f);
    chain_losses_backward(f.data_ptr<float>(), x.data_ptr<float>(), weight_data(w),
                          static_cast<int>(x.size(0)), static_cast<int>(x.size(1)),
                          static_cast<int>(x.size(2)), scalar(grad[0]), scalar(grad[1]),
                          df.data_ptr<float>());
    return {df, torch::Tensor(), torch::Tensor()};
  }
  // An autograd function's tensor arguments must be defined: no weight is
  // an empty one.
  static const float* weight_data(const torch::Tensor& w) {
    return w.numel() > 0 ? w.data_ptr<float>() : nullptr;
  }
};

}  // namespace

std::pair<torch::Tensor, torch::Tensor> chain_losses(const torch::Tensor& frames,
                                                     const torch::Tensor& truth,
                                                     const torch::Tensor& weight) {
  const auto out = ChainLosses::apply(frames, truth,
                                      weight.defined() ? weight : torch::empty({0}));
  return {out[0], out[1]};
}

torch::Tensor kl_loss(const torch::Tensor& mu, const torch::Tensor& logvar) {
  return (-0.5 * (1.0 + logvar - mu.pow(2) - logvar.exp())).mean();
}

torch::Tensor l2_loss(const torch::nn::Module& net) {
  torch::Tensor sum = torch::zeros({});
  std::int64_t count = 0;
  for (const auto& p : net.parameters()) {
    if (p.dim() < 2) continue;
    sum = sum + p.pow(2).sum();
    count += p.numel();
  }
  return count == 0 ? sum : sum / static_cast<double>(count);
}

void add_l2_gradient(const torch::nn::Module& net, double scale) {
  torch::NoGradGuard no_grad;
  std::int64_t count = 0;
  for (const auto& p : net.parameters()) {
    if (p.dim() >= 2) count += p.numel();
  }
  if (count == 0) return;
  // d/dw of sum(w^2) / count.
  const double factor = 2.0 * scale / static_cast<double>(count);
  for (auto p : net.parameters()) {
    if (p.dim() < 2) continue;
    if (p.grad().defined()) {
      p.mutable_grad().add_(p.detach(), factor);
    } else {
      p.mutable_grad() = p.detach() * factor;
    }
  }
}

namespace {

// batch_loss; with `l2_in_graph` false the L2 term's value is in the total
// but not on the tape (the caller adds its gradient: add_l2_gradient).
LossTerms batch_loss_terms(SeqNet& net, const torch::Tensor& truth, bool sample, double kl_weight,
                           bool bidirectional, double l2_weight, const torch::Tensor& frame_weight,
                           bool l2_in_graph) {
  const auto n = static_cast<int>(truth.size(0));
  const auto batch = static_cast<int>(truth.size(1));
  LossTerms l;
  if (bidirectional) {
    // Both chains as one batch of 2 B sequences: the same numbers as two
    // runs, in half the steps (forward first, +s0; backward, -s0).
    const LstmState f0 = net->initial_state(batch, 1.0), b0 = net->initial_state(batch, -1.0);
    const LstmState both{torch::cat({std::get<0>(f0), std::get<0>(b0)}, 1),
                         torch::cat({std::get<1>(f0), std::get<1>(b0)}, 1)};
    const torch::Tensor starts = torch::cat({truth.slice(0, 0, 1), truth.slice(0, n - 1, n)}, 1);
    const Chain c = net->run(starts, n, both, sample);
    std::tie(l.recon, l.bidir) = chain_losses(c.frames, truth, frame_weight);
    // Both halves are the same size: the mean over both is the mean of the
    // two chains' means.
    l.kl = kl_loss(c.mu, c.logvar);
  } else {
    const Chain f = net->run(truth.slice(0, 0, 1), n, net->initial_state(batch, 1.0), sample);
    l.kl = kl_loss(f.mu, f.logvar);
    // One direction: its reconstruction counted twice, to keep the scale.
    l.recon = 2.0 * frame_distances(f.frames - truth, frame_weight).sum();
    l.bidir = torch::zeros({});
  }
  if (l2_in_graph) {
    l.l2 = l2_loss(*net);
  } else {
    torch::NoGradGuard no_grad;
    l.l2 = l2_loss(*net);
  }
  l.total = l.recon + 0.5 * l.bidir + 0.1 * (kl_weight * l.kl + l2_weight * l.l2);
  return l;
}

}  // namespace

LossTerms batch_loss(SeqNet& net, const torch::Tensor& truth, bool sample, double kl_weight,
                     bool bidirectional, double l2_weight, const torch::Tensor& frame_weight) {
  return batch_loss_terms(net, truth, sample, kl_weight, bidirectional, l2_weight, frame_weight,
                          true);
}

LossTerms train_step(SeqNet& net, Adam& adam, const torch::Tensor& truth, double kl_weight,
                     bool bidirectional, double l2_weight, const torch::Tensor& frame_weight,
                     double clip_gradient) {
  net->collect_dense_gradients(true);
  LossTerms l;
  try {
    // The L2 term's gradient is added after backward: on the tape it was a
    // few passes over every weight, forward and backward, for 2 w / count.
    l = batch_loss_terms(net, truth, true, kl_weight, bidirectional, l2_weight, frame_weight,
                         false);
  } catch (...) {
    net->collect_dense_gradients(false);
    throw;
  }
  net->collect_dense_gradients(false);
  l.total.backward();
  net->finish_gradients();
  add_l2_gradient(*net, 0.1 * l2_weight);
  if (clip_gradient > 0) l.gradient_norm = adam.clip(clip_gradient);
  adam.step();
  return l;
}

Adam::Adam(std::vector<torch::Tensor> parameters, double learning_rate)
    : params_(std::move(parameters)), lr_(learning_rate) {
  for (const auto& p : params_) {
    m_.push_back(torch::zeros_like(p));
    v_.push_back(torch::zeros_like(p));
  }
}

double Adam::clip(double max_norm) {
  torch::NoGradGuard no_grad;
  double sum = 0;
  for (const torch::Tensor& p : params_) {
    if (!p.grad().defined()) continue;
    const torch::Tensor g = p.grad().contiguous();
    const float* x = g.data_ptr<float>();
    for (std::int64_t i = 0, n = g.numel(); i < n; ++i) sum += static_cast<double>(x[i]) * x[i];
  }
  const double norm = std::sqrt(sum);
  if (norm > max_norm) {
    for (torch::Tensor& p : params_) {
      if (p.grad().defined()) p.mutable_grad().mul_(max_norm / norm);
    }
  }
  return norm;
}

void Adam::step() {
  torch::NoGradGuard no_grad;
  ++steps_;
  const double b1 = 0.9, b2 = 0.999, eps = 1e-8;
  const double c1 = 1.0 - std::pow(b1, static_cast<double>(steps_));
  const double c2 = 1.0 - std::pow(b2, static_cast<double>(steps_));
  // One pass per parameter (train_kernel.hpp) where libtorch's operations
  // took ten.
  const AdamConstants k{static_cast<float>(b1),  static_cast<float>(1.0 - b1),
                        static_cast<float>(b2),  static_cast<float>(1.0 - b2),
                        static_cast<float>(c1),  static_cast<float>(c2),
                        static_cast<float>(eps), static_cast<float>(-lr_)};
  for (std::size_t i = 0; i < params_.size(); ++i) {
    torch::Tensor& p = params_[i];
    if (!p.grad().defined()) continue;
    torch::Tensor& g = p.mutable_grad();
    if (!g.is_contiguous()) g = g.contiguous();
    TORCH_CHECK(p.is_contiguous() && p.scalar_type() == torch::kFloat32 &&
                    g.scalar_type() == torch::kFloat32 && g.sizes() == p.sizes(),
                "Adam: float parameters and gradients of their shape");
    adam_update(p.data_ptr<float>(), g.data_ptr<float>(), m_[i].data_ptr<float>(),
                v_[i].data_ptr<float>(), static_cast<std::size_t>(p.numel()), k);
  }
}

namespace {

NamedArray to_array(const std::string& name, const torch::Tensor& t) {
  NamedArray a;
  a.name = name;
  const torch::Tensor c = t.detach().contiguous().to(torch::kFloat32);
  a.shape.assign(c.sizes().begin(), c.sizes().end());
  a.values.assign(c.data_ptr<float>(), c.data_ptr<float>() + c.numel());
  return a;
}

void copy_into(torch::Tensor& target, const NamedArray& a, const std::string& file,
               const std::string& what) {
  const std::vector<std::int64_t> want(target.sizes().begin(), target.sizes().end());
  if (a.shape != want) {
    auto str = [](const std::vector<std::int64_t>& s) {
      std::string out;
      for (auto d : s) out += (out.empty() ? "" : "x") + std::to_string(d);
      return out.empty() ? std::string("scalar") : out;
    };
    throw InputError(Location{file, 0, 0}, what + " " + a.name,
                     "shape " + str(a.shape) + ", the network needs " + str(want));
  }
  torch::NoGradGuard no_grad;
  target.copy_(torch::from_blob(const_cast<float*>(a.values.data()),
                                {static_cast<std::int64_t>(a.values.size())}, torch::kFloat32)
                   .view(target.sizes()));
}

const NamedArray& find_array(const std::vector<NamedArray>& arrays, const std::string& name,
                             const std::string& file, const std::string& what) {
  for (const NamedArray& a : arrays) {
    if (a.name == name) return a;
  }
  throw InputError(Location{file, 0, 0}, what + " " + name, "missing from the file");
}

}  // namespace

std::vector<NamedArray> Adam::state(const std::vector<std::string>& names) const {
  std::vector<NamedArray> out;
  for (std::size_t k = 0; k < params_.size(); ++k) {
    out.push_back(to_array("m." + names[k], m_[k]));
    out.push_back(to_array("v." + names[k], v_[k]));
  }
  NamedArray steps;
  steps.name = "steps";
  steps.shape = {1};
  // Exact as a float up to 2^24 steps.
  steps.values = {static_cast<float>(steps_)};
  out.push_back(steps);
  return out;
}

void Adam::restore(const std::vector<NamedArray>& state, const std::vector<std::string>& names,
                   const std::string& file) {
  for (std::size_t k = 0; k < params_.size(); ++k) {
    copy_into(m_[k], find_array(state, "m." + names[k], file, "optimiser"), file, "optimiser");
    copy_into(v_[k], find_array(state, "v." + names[k], file, "optimiser"), file, "optimiser");
  }
  const NamedArray& steps = find_array(state, "steps", file, "optimiser");
  if (steps.values.size() != 1 || steps.values[0] < 0.0F) {
    throw InputError(Location{file, 0, 0}, "optimiser steps", "not one count");
  }
  steps_ = static_cast<std::int64_t>(steps.values[0]);
}

std::vector<NamedArray> save_parameters(const SeqNetImpl& net) {
  std::vector<NamedArray> out;
  for (const auto& item : net.named_parameters()) out.push_back(to_array(item.key(), item.value()));
  return out;
}

void load_parameters(SeqNetImpl& net, const std::vector<NamedArray>& arrays,
                     const std::string& file) {
  auto params = net.named_parameters();
  if (arrays.size() != params.size()) {
    throw InputError(Location{file, 0, 0}, "parameters",
                     std::to_string(arrays.size()) + " arrays, the network has " +
                         std::to_string(params.size()));
  }
  for (auto& item : params) {
    copy_into(item.value(), find_array(arrays, item.key(), file, "parameter"), file, "parameter");
  }
}

SeqNet network_for(const ModelFile& model, const std::string& file) {
  MeshGraph graph;
  if (model.shape.kind == ModelKind::mesh) {
    graph = mesh_graph(model.shape.vertex_count, model.triangles);
  }
  SeqNet net(model.shape, graph);
  load_parameters(*net, model.parameters, file);
  return net;
}

}  // namespace animrt::seqnet
