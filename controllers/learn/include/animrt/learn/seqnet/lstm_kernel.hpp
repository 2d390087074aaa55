#pragma once
// The LSTM cell's element-wise part of one training step as plain loops:
// the gates' nonlinearities and the cell update forward, their gradients
// backward. libtorch runs them as a dozen operations per layer and step,
// forward and backward, each dispatched on a 16 x 128 tensor; here they
// are one pass. No libtorch here: the autograd node (lstm_step.cpp) calls
// it. Gates are four blocks of `count` entries (hidden x batch) in the
// order input, forget, cell, output (as libtorch's LSTM); the states are
// one block each, laid out alike.

#include <cstddef>

namespace animrt::seqnet {

// `gates` holds the pre-activations a = W [x h] + b and is overwritten by
// the activations (sigmoid, sigmoid, tanh, sigmoid). c' = f c + i g,
// h' = o tanh(c'); tanh(c') is kept for backward. tanh is 2 sigmoid(2a) - 1
// with exp in plain arithmetic (vector_exp.hpp), so the loop runs a vector
// of entries at a time.
void lstm_cell_forward(float* gates, const float* c, float* c_next, float* h_next, float* tanh_c,
                       int count);

// From the activations, c, tanh(c') and the gradients of h' and c' to the
// gradient of the pre-activations `d_gates` (four blocks) and of c,
// `gc_prev`. h's gradient is `gh_a` + `gh_b`; `gh_b` may be null (zero).
void lstm_cell_backward(const float* gates, const float* c, const float* tanh_c, const float* gh_a,
                        const float* gh_b, const float* gc, float* d_gates, float* gc_prev,
                        int count);

// tanh of `count` numbers in place, as the cell's (the network's tanh
// after its convolutions and dense layer).
void tanh_in_place(float* y, std::size_t count);

}  // namespace animrt::seqnet
