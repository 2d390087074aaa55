#include "animrt/learn/seqnet/lstm_step.hpp"

#include <cstring>

#include "animrt/learn/seqnet/dense_kernel.hpp"
#include "animrt/learn/seqnet/lstm_kernel.hpp"

namespace animrt::seqnet {

c10::intrusive_ptr<LstmPack> pack_lstm(torch::nn::LSTMImpl& lstm) {
  const auto& o = lstm.options;
  TORCH_CHECK(o.bias() && !o.bidirectional() && !o.batch_first() && o.proj_size() == 0,
              "fused LSTM step: plain LSTM only");
  torch::NoGradGuard no_grad;
  auto p = c10::make_intrusive<LstmPack>();
  p->layers = static_cast<int>(o.num_layers());
  p->hidden = o.hidden_size();
  const auto params = lstm.named_parameters();
  const auto gates = static_cast<int>(4 * p->hidden);
  for (int l = 0; l < p->layers; ++l) {
    const std::string k = "_l" + std::to_string(l);
    const torch::Tensor w =
        torch::cat({params["weight_ih" + k].detach(), params["weight_hh" + k].detach()}, 1)
            .contiguous();
    const auto cols = static_cast<int>(w.size(1));
    p->in.push_back(cols - p->hidden);
    auto& f = p->forward.emplace_back(dense_packed_size(gates, cols));
    auto& b = p->backward.emplace_back(dense_packed_size(cols, gates));
    pack_dense_rows(w.data_ptr<float>(), gates, cols, cols, 1, f.data());
    pack_dense_rows(w.data_ptr<float>(), cols, gates, 1, cols, b.data());
    const torch::Tensor bias =
        (params["bias_ih" + k].detach() + params["bias_hh" + k].detach()).contiguous();
    p->bias.emplace_back(bias.data_ptr<float>(), bias.data_ptr<float>() + gates);
  }
  p->inputs.resize(static_cast<std::size_t>(p->layers));
  p->grads.resize(static_cast<std::size_t>(p->layers));
  return p;
}

namespace {

// y [rows, B] = packed x [cols, B] (+ bias).
void product(const std::vector<float>& packed, const float* bias, const torch::Tensor& x, int rows,
             torch::Tensor& y) {
  dense_batch_inner_threads(packed.data(), bias, x.data_ptr<float>(), rows,
                            static_cast<int>(x.size(0)), static_cast<int>(x.size(1)),
                            y.data_ptr<float>());
}

struct LstmStep : torch::autograd::Function<LstmStep> {
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx,
                                                const torch::Tensor& z, const torch::Tensor& h,
                                                const torch::Tensor& c,
                                                const c10::intrusive_ptr<LstmPack>& p) {
    const std::int64_t batch = z.size(0), hidden = p->hidden, in = p->in[0];
    TORCH_CHECK(z.dim() == 2 && z.size(1) == in && z.scalar_type() == torch::kFloat32 &&
                    h.sizes() == c.sizes() && h.size(0) == p->layers && h.size(1) == hidden &&
                    h.size(2) == batch,
                "fused LSTM step: z must be float [B, in], h and c [layers, hidden, B]");
    const torch::Tensor hc = h.contiguous(), cc = c.contiguous();
    torch::Tensor h_next = torch::empty_like(hc), c_next = torch::empty_like(cc);
    const auto count = static_cast<int>(hidden * batch);
    std::vector<torch::Tensor> gates, tanh_c;
    std::vector<std::int64_t> slots;
    for (int l = 0; l < p->layers; ++l) {
      const auto k = static_cast<std::size_t>(l);
      const std::int64_t width = p->in[k];
      // [x h] with the batch innermost: z transposed, or the layer below's h.
      torch::Tensor xh = torch::empty({width + hidden, batch}, z.options());
      float* xp = xh.data_ptr<float>();
      if (l == 0) {
        xh.slice(0, 0, width).copy_(z.t());
      } else {
        std::memcpy(xp, h_next[l - 1].data_ptr<float>(), sizeof(float) * count);
      }
      std::memcpy(xp + width * batch, hc[l].data_ptr<float>(), sizeof(float) * count);
      torch::Tensor a = torch::empty({4 * hidden, batch}, z.options());
      product(p->forward[k], p->bias[k].data(), xh, static_cast<int>(4 * hidden), a);
      torch::Tensor t = torch::empty({hidden, batch}, z.options());
      lstm_cell_forward(a.data_ptr<float>(), cc[l].data_ptr<float>(), c_next[l].data_ptr<float>(),
                        h_next[l].data_ptr<float>(), t.data_ptr<float>(), count);
      auto& inputs = p->inputs[k];
      slots.push_back(static_cast<std::int64_t>(inputs.size()));
      inputs.push_back(xh);
      p->grads[k].emplace_back();
      gates.push_back(a);
      tanh_c.push_back(t);
    }
    ctx->saved_data["p"] = c10::IValue::make_capsule(p);
    ctx->saved_data["gates"] = gates;
    ctx->saved_data["tanh_c"] = tanh_c;
    ctx->saved_data["c"] = cc;
    ctx->saved_data["slots"] = slots;
    return {h_next, c_next};
  }

  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grad) {
    const auto p = c10::static_intrusive_pointer_cast<LstmPack>(ctx->saved_data["p"].toCapsule());
    const std::vector<torch::Tensor> gates = ctx->saved_data["gates"].toTensorVector();
    const std::vector<torch::Tensor> tanh_c = ctx->saved_data["tanh_c"].toTensorVector();
    const std::vector<std::int64_t> slots = ctx->saved_data["slots"].toIntVector();
    const torch::Tensor c = ctx->saved_data["c"].toTensor();
    const torch::Tensor gh = grad[0].contiguous(), gc = grad[1].contiguous();
    const std::int64_t hidden = p->hidden, batch = c.size(2);
    const auto count = static_cast<int>(hidden * batch);
    torch::Tensor gh_prev = torch::empty_like(c), gc_prev = torch::empty_like(c);
    torch::Tensor from_above;  // the gradient of layer l's output from layer l + 1's input
    for (int l = p->layers - 1; l >= 0; --l) {
      const auto k = static_cast<std::size_t>(l);
      const std::int64_t width = p->in[k];
      torch::Tensor d = torch::empty({4 * hidden, batch}, c.options());
      lstm_cell_backward(
          gates[k].data_ptr<float>(), c[l].data_ptr<float>(), tanh_c[k].data_ptr<float>(),
          gh[l].data_ptr<float>(), from_above.defined() ? from_above.data_ptr<float>() : nullptr,
          gc[l].data_ptr<float>(), d.data_ptr<float>(), gc_prev[l].data_ptr<float>(), count);
      torch::Tensor gxh = torch::empty({width + hidden, batch}, c.options());
      product(p->backward[k], nullptr, d, static_cast<int>(width + hidden), gxh);
      std::memcpy(gh_prev[l].data_ptr<float>(), gxh.data_ptr<float>() + width * batch,
                  sizeof(float) * count);
      from_above = gxh.slice(0, 0, width);  // the leading rows: contiguous
      p->grads[k][static_cast<std::size_t>(slots[k])] = d;
    }
    return {from_above.t(), gh_prev, gc_prev, torch::Tensor()};
  }
};

}  // namespace

std::pair<torch::Tensor, torch::Tensor> lstm_step(const torch::Tensor& z, const torch::Tensor& h,
                                                  const torch::Tensor& c,
                                                  const c10::intrusive_ptr<LstmPack>& pack) {
  const torch::autograd::variable_list next = LstmStep::apply(z, h, c, pack);
  return {next[0], next[1]};
}

std::vector<std::pair<std::string, torch::Tensor>> lstm_gradients(const LstmPack& pack) {
  torch::NoGradGuard no_grad;
  std::vector<std::pair<std::string, torch::Tensor>> out;
  for (int l = 0; l < pack.layers; ++l) {
    const auto k = static_cast<std::size_t>(l);
    std::vector<torch::Tensor> x, g;
    for (std::size_t s = 0; s < pack.grads[k].size(); ++s) {
      if (!pack.grads[k][s].defined()) continue;
      x.push_back(pack.inputs[k][s]);
      g.push_back(pack.grads[k][s]);
    }
    if (g.empty()) continue;
    // [4H, steps B] by [steps B, in + H]: every step's d [x h]^T summed.
    const torch::Tensor gs = torch::cat(g, 1), xs = torch::cat(x, 1);
    const torch::Tensor w = torch::mm(gs, xs.t()), b = gs.sum(1);
    const std::string n = "_l" + std::to_string(l);
    out.emplace_back("weight_ih" + n, w.slice(1, 0, pack.in[k]));
    out.emplace_back("weight_hh" + n, w.slice(1, pack.in[k]));
    out.emplace_back("bias_ih" + n, b);
    out.emplace_back("bias_hh" + n, b);
  }
  return out;
}

}  // namespace animrt::seqnet
