#pragma once
// The training step's element-wise passes over whole tensors as plain
// loops: the two chains' losses and their gradient, and Adam's update.
// libtorch ran each as a dozen operations, every one a pass over memory
// (the frames of an iteration are 9 MB at 482 vertices, the weights
// 8.5 MB); here each is one pass. No libtorch here: network.cpp calls them.

#include <cstddef>

namespace animrt::seqnet {

// Frames F [n, 2B, D] (the forward chain in the first B sequences, the
// backward chain in the last B) against the truth X [n, B, D]:
//   recon = sum_t mean (F^f_t - X_t)^2 + mean (F^b_t - X_{n-1-t})^2
//   bidir = sum_t mean (F^f_t - F^b_{n-1-t})^2
// each mean over the B x D entries of a frame; sums in double. `weight`
// [D] (null: all 1) weighs each of a frame's D numbers in its squares.
void chain_loss_sums(const float* frames, const float* truth, const float* weight, int n,
                     int batch, int dims, double* recon, double* bidir);

// Their gradient with respect to F, for the gradients `g_recon` and
// `g_bidir` of the two sums, into `d_frames` [n, 2B, D].
void chain_losses_backward(const float* frames, const float* truth, const float* weight, int n,
                           int batch, int dims, float g_recon, float g_bidir, float* d_frames);

// One Adam step on `count` numbers, in libtorch's order of operations:
// m = b1 m + (1 - b1) g, v = b2 v + (1 - b2) g g,
// p -= lr (m / c1) / (sqrt(v / c2) + eps), then g = 0.
// The constants as libtorch rounds them: each its double value as a float
// (one_b1 = float(1 - b1), not 1 - float(b1)).
struct AdamConstants {
  float b1, one_b1, b2, one_b2, c1, c2, eps, minus_lr;
};
void adam_update(float* p, float* g, float* m, float* v, std::size_t count, const AdamConstants& k);

}  // namespace animrt::seqnet
