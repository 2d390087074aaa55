#include "animrt/learn/seqnet/lstm_step.hpp"

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
  for (int l = 0; l < p->layers; ++l) {
    const std::string k = "_l" + std::to_string(l);
    const torch::Tensor wi = params["weight_ih" + k].detach(), wh = params["weight_hh" + k].detach();
    p->in.push_back(wi.size(1));
    p->weight_t.push_back(torch::cat({wi, wh}, 1).t().contiguous());
    p->weight_x.push_back(wi.contiguous());
    p->weight_h.push_back(wh.contiguous());
    p->bias.push_back(params["bias_ih" + k].detach() + params["bias_hh" + k].detach());
  }
  p->inputs.resize(static_cast<std::size_t>(p->layers));
  p->grads.resize(static_cast<std::size_t>(p->layers));
  return p;
}

namespace {

struct LstmStep : torch::autograd::Function<LstmStep> {
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx,
                                                const torch::Tensor& z, const torch::Tensor& h,
                                                const torch::Tensor& c,
                                                const c10::intrusive_ptr<LstmPack>& p) {
    const std::int64_t batch = z.size(0), hidden = p->hidden;
    TORCH_CHECK(z.dim() == 2 && z.size(1) == p->in[0] && z.scalar_type() == torch::kFloat32 &&
                    h.sizes() == c.sizes() && h.size(0) == p->layers && h.size(1) == batch &&
                    h.size(2) == hidden,
                "fused LSTM step: z must be float [B, in], h and c [layers, B, hidden]");
    const torch::Tensor hc = h.contiguous(), cc = c.contiguous();
    torch::Tensor h_next = torch::empty_like(hc), c_next = torch::empty_like(cc);
    std::vector<torch::Tensor> gates, tanh_c;
    std::vector<std::int64_t> slots;
    torch::Tensor x = z.contiguous();
    for (int l = 0; l < p->layers; ++l) {
      const torch::Tensor xh = torch::cat({x, hc[l]}, 1);
      torch::Tensor a = torch::addmm(p->bias[l], xh, p->weight_t[l]);
      torch::Tensor t = torch::empty({batch, hidden}, z.options());
      torch::Tensor hn = h_next[l], cn = c_next[l];
      lstm_cell_forward(a.data_ptr<float>(), cc[l].data_ptr<float>(), cn.data_ptr<float>(),
                        hn.data_ptr<float>(), t.data_ptr<float>(), static_cast<int>(batch),
                        static_cast<int>(hidden));
      auto& inputs = p->inputs[static_cast<std::size_t>(l)];
      slots.push_back(static_cast<std::int64_t>(inputs.size()));
      inputs.push_back(xh);
      p->grads[static_cast<std::size_t>(l)].emplace_back();
      gates.push_back(a);
      tanh_c.push_back(t);
      x = hn;
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
    const std::int64_t batch = c.size(1), hidden = p->hidden;
    torch::Tensor gh_prev = torch::empty_like(c), gc_prev = torch::empty_like(c);
    torch::Tensor from_above;  // the gradient of layer l's output from layer l + 1's input
    for (int l = p->layers - 1; l >= 0; --l) {
      const auto k = static_cast<std::size_t>(l);
      torch::Tensor d = torch::empty({batch, 4 * hidden}, c.options());
      torch::Tensor gcp = gc_prev[l];
      lstm_cell_backward(gates[k].data_ptr<float>(), c[l].data_ptr<float>(),
                         tanh_c[k].data_ptr<float>(), gh[l].data_ptr<float>(),
                         from_above.defined() ? from_above.data_ptr<float>() : nullptr,
                         gc[l].data_ptr<float>(), d.data_ptr<float>(), gcp.data_ptr<float>(),
                         static_cast<int>(batch), static_cast<int>(hidden));
      torch::Tensor ghp = gh_prev[l];
      torch::mm_out(ghp, d, p->weight_h[k]);
      from_above = torch::mm(d, p->weight_x[k]);
      p->grads[k][static_cast<std::size_t>(slots[k])] = d;
    }
    return {from_above, gh_prev, gc_prev, torch::Tensor()};
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
    const torch::Tensor gs = torch::cat(g), xs = torch::cat(x);
    const torch::Tensor w = torch::mm(gs.t(), xs), b = gs.sum(0);
    const std::string n = "_l" + std::to_string(l);
    out.emplace_back("weight_ih" + n, w.slice(1, 0, pack.in[k]));
    out.emplace_back("weight_hh" + n, w.slice(1, pack.in[k]));
    out.emplace_back("bias_ih" + n, b);
    out.emplace_back("bias_hh" + n, b);
  }
  return out;
}

}  // namespace animrt::seqnet
