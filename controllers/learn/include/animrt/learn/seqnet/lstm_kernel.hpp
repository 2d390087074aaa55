#pragma once
// The LSTM cell's element-wise part of one training step as plain loops:
// the gates' nonlinearities and the cell update forward, their gradients
// backward. libtorch runs them as a dozen operations per layer and step,
// forward and backward, each dispatched on a 16 x 128 tensor; here they
// are one pass over the batch. No libtorch here: the autograd node
// (lstm_step.cpp) calls it. Layouts are row-major, one row per sequence:
// gates [batch, 4 hidden] in the order input, forget, cell, output (as
// libtorch's LSTM), states [batch, hidden].

namespace animrt::seqnet {

// `gates` holds the pre-activations a = W [x h] + b and is overwritten by
// the activations (sigmoid, sigmoid, tanh, sigmoid). c' = f c + i g,
// h' = o tanh(c'); tanh(c') is kept for backward.
void lstm_cell_forward(float* gates, const float* c, float* c_next, float* h_next, float* tanh_c,
                       int batch, int hidden);

// From the activations, c, tanh(c') and the gradients of h' and c'
// (`gh_a` + `gh_b`, either may be null; `gc` may be null) to the gradient of
// the pre-activations `d_gates` [batch, 4 hidden] and of c, `gc_prev`.
void lstm_cell_backward(const float* gates, const float* c, const float* tanh_c, const float* gh_a,
                        const float* gh_b, const float* gc, float* d_gates, float* gc_prev,
                        int batch, int hidden);

}  // namespace animrt::seqnet
