#pragma once
// One step of a multi-layer LSTM (libtorch's nn::LSTM: gates in the order
// input, forget, cell, output; biases b_ih and b_hh) as one autograd node:
// per layer one product of [x h] with the stacked weights and one pass of
// lstm_kernel.hpp's loops, forward and backward. The chain is
// autoregressive (each step's input is made from the previous step's
// output), so the steps cannot be one call over the window; libtorch's LSTM
// ran a few dozen operations per step instead of a few.
//
// As the dense layers' tape (network.cpp), the weights stay outside
// autograd: the pack keeps every step's [x h] and the gates' gradient, and
// lstm_gradients() forms each weight's gradient in one product after
// backward.

#include <torch/torch.h>

#include <string>
#include <utility>
#include <vector>

namespace animrt::seqnet {

struct LstmPack : torch::CustomClassHolder {
  int layers = 0;
  std::int64_t hidden = 0;
  std::vector<std::int64_t> in;           // each layer's input width
  std::vector<torch::Tensor> weight_t;    // [in + H, 4H]: (W_ih W_hh)^T, forward
  std::vector<torch::Tensor> weight_x;    // [4H, in]: W_ih, the input's gradient
  std::vector<torch::Tensor> weight_h;    // [4H, H]: W_hh, the state's gradient
  std::vector<torch::Tensor> bias;        // [4H]: b_ih + b_hh
  // Per layer, per step: [x h] and the gates' pre-activation gradient
  // (undefined where backward did not reach).
  std::vector<std::vector<torch::Tensor>> inputs, grads;
};

// The weights of `lstm` as they are now (no projection, one direction,
// batch second, with biases).
c10::intrusive_ptr<LstmPack> pack_lstm(torch::nn::LSTMImpl& lstm);

// z [B, in], state h and c [layers, B, H] -> the next state; the output is
// the next h's last layer. Gradients flow to z and the state.
std::pair<torch::Tensor, torch::Tensor> lstm_step(const torch::Tensor& z, const torch::Tensor& h,
                                                  const torch::Tensor& c,
                                                  const c10::intrusive_ptr<LstmPack>& pack);

// The gradients of the LSTM's parameters (by name) over the pack's steps
// that got one; empty if none did.
std::vector<std::pair<std::string, torch::Tensor>> lstm_gradients(const LstmPack& pack);

}  // namespace animrt::seqnet
