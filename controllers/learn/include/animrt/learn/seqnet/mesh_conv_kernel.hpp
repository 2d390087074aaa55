#pragma once
// The mesh convolution of the training step (Eq. 2) as plain loops over
// one pass of the vertices: the 1-ring gather, both 9 x 9 weight products
// and the bias per vertex, and backward the gradients of input, weights
// and bias in two passes. Activations are [V, C, B] (vertex, channel,
// batch; the batch innermost), so every product runs over B contiguous
// numbers per weight: libtorch's sparse product and its BLAS calls on
// [V B, 9] x [9, 9] spent most of their time in per-call overhead and
// packing such thin matrices.
// No libtorch here: the network's autograd node (network.cpp) calls it.

#include <cstdint>
#include <vector>

namespace animrt::seqnet {

// A V x V sparse matrix by rows: row i gathers x_j with weight w for each
// (j, w) in [start[i], start[i + 1]), columns ascending.
struct RingRows {
  int vertices = 0;
  std::vector<std::int32_t> start;  // V + 1
  std::vector<std::int32_t> col;
  std::vector<float> weight;
};

// The matrix with weight[k] at (rows[k], cols[k]); a pair given twice is
// summed, as coalescing a sparse tensor does.
RingRows ring_rows(int vertices, const std::vector<std::int64_t>& rows,
                   const std::vector<std::int64_t>& cols, const std::vector<float>& weight);

// Batch entries the kernels take at once (one AVX-512 vector).
constexpr int kConvLanes = 16;

struct ConvShape {
  int vertices = 0, in = 0, out = 0, batch = 0;
};

// Vertices [first, last): ring = M x and y = W1 x + W2 ring + b per vertex
// and batch entry (weights [out, in], row-major).
void mesh_conv_forward(const ConvShape& s, const RingRows& m, const float* x, const float* w_self,
                       const float* w_ring, const float* bias, float* ring, float* y, int first,
                       int last);

// Backward, first pass over vertices [first, last): g = dL/dy (times
// 1 - y^2 when `squashed` is given: y = tanh(.) was the output);
// grad_x = W1^T g; through = W2^T g, which the second pass spreads by the
// adjoint; the weight and bias gradients of these vertices are added to
// acc_self and acc_ring ([out, in, kConvLanes]) and acc_bias ([out,
// kConvLanes]), which the caller sums over their last dimension.
void mesh_conv_backward_local(const ConvShape& s, const float* x, const float* ring,
                              const float* squashed, const float* grad_y, const float* w_self,
                              const float* w_ring, float* grad_x, float* through, float* acc_self,
                              float* acc_ring, float* acc_bias, int first, int last);

// Backward, second pass over vertices [first, last): grad_x += M^T through
// (`adjoint` is M^T by rows).
void mesh_conv_backward_ring(const ConvShape& s, const RingRows& adjoint, const float* through,
                             float* grad_x, int first, int last);

}  // namespace animrt::seqnet
