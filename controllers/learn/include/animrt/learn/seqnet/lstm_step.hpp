#pragma once
// One step of a multi-layer LSTM (libtorch's nn::LSTM: gates in the order
// input, forget, cell, output; biases b_ih and b_hh) as one autograd node:
// per layer one product of the stacked weights with [x h] (dense_kernel.hpp's
// loops, the batch innermost, the weights packed once per chain) and one
// pass of lstm_kernel.hpp's loops, forward and backward. The chain is
// autoregressive (each step's input is made from the previous step's
// output), so the steps cannot be one call over the window; libtorch's LSTM
// ran a few dozen operations per step instead of a few.
//
// As the dense layers' tape (network.cpp), the weights stay outside
// autograd: the pack keeps every step's [x h] and the gates' gradient, and
// lstm_gradients() forms each weight's gradient in one product after
// backward.

#include <torch/torch.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace animrt::seqnet {

struct LstmPack : torch::CustomClassHolder {
  int layers = 0;
  std::int64_t hidden = 0;
  std::vector<std::int64_t> in;  // each layer's input width
  // Per layer, W = (W_ih W_hh) [4H, in + H] packed for forward and W^T
  // for the gradient of [x h]; the bias b_ih + b_hh.
  std::vector<std::vector<float>> forward, backward, bias;
  // Per layer, per step: [x h] and the gates' pre-activation gradient,
  // the batch innermost (undefined where backward did not reach).
  std::vector<std::vector<torch::Tensor>> inputs, grads;
};

// The weights of `lstm` as they are now (no projection, one direction,
// batch second, with biases).
c10::intrusive_ptr<LstmPack> pack_lstm(torch::nn::LSTMImpl& lstm);

// z [B, in], state h and c [layers, H, B] (the batch innermost) -> the
// next state so laid out; the output is the next h's last layer, [H, B].
// Gradients flow to z and the state.
std::pair<torch::Tensor, torch::Tensor> lstm_step(const torch::Tensor& z, const torch::Tensor& h,
                                                  const torch::Tensor& c,
                                                  const c10::intrusive_ptr<LstmPack>& pack);

// The gradients of the LSTM's parameters (by name) over the pack's steps
// that got one; empty if none did.
std::vector<std::pair<std::string, torch::Tensor>> lstm_gradients(const LstmPack& pack);

}  // namespace animrt::seqnet
