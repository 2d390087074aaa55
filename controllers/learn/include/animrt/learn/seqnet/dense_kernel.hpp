#pragma once
// The dense layers' products of one training step as plain loops on
// activations with the batch innermost ([K, B]): y = M x (+ b), M an
// N x K matrix packed once per chain. At a step the batch is a few rows
// (16 with both chains of 8 windows) against 9V x 256 and 128 x 9V
// weights; BLAS copies the whole weight matrix into its packed layout at
// every such call, which took longer than the products themselves.
// No libtorch here: the network's autograd node (network.cpp) calls it.

#include <cstddef>

namespace animrt::seqnet {

// Output rows a packed block holds.
constexpr int kDenseRows = 8;

// M (rows x cols, element (i, j) at m[i * row_stride + j * col_stride])
// packed for dense_batch_inner: block r holds rows [8 r, 8 r + 8) as
// [cols][8], rows past the end zero. `packed` has dense_packed_size().
std::size_t dense_packed_size(int rows, int cols);
void pack_dense_rows(const float* m, int rows, int cols, std::ptrdiff_t row_stride,
                     std::ptrdiff_t col_stride, float* packed);

// y[i][b] = bias[i] + sum_k M[i][k] x[k][b] for the output rows of blocks
// [first_block, last_block), b < batch; x is [cols, batch], y [rows,
// batch], both contiguous; bias may be null (zero).
void dense_batch_inner(const float* packed, const float* bias, const float* x, int rows, int cols,
                       int batch, float* y, int first_block, int last_block);

// dense_batch_inner over all the output rows, the blocks split between
// libtorch's threads (defined beside the network's dense node, network.cpp).
void dense_batch_inner_threads(const float* packed, const float* bias, const float* x, int rows,
                               int cols, int batch, float* y);

}  // namespace animrt::seqnet
