#include "animrt/learn/seqnet/dense_kernel.hpp"

#include <algorithm>

#include "vector_clones.hpp"

// The batch loops are marked for the vectoriser (as mesh_conv_kernel.cpp).

namespace animrt::seqnet {

namespace {

constexpr auto kRows = static_cast<std::size_t>(kDenseRows);
// Batch entries a pass takes at once (one AVX-512 vector).
constexpr std::size_t kLanes = 16;

std::size_t blocks(int rows) {
  return (static_cast<std::size_t>(rows) + kRows - 1) / kRows;
}

// One block of 8 output rows for batch entries [0, width) of a chunk: the
// 8 x width sums stay in vector registers while the block's weights
// stream past once, in the order they are stored. W > 0: the width known
// at compile time (a full chunk); W = 0: `w`, the last chunk's.
template <std::size_t W>
[[gnu::always_inline]] inline void block_chunk(const float* __restrict p,
                                               const float* __restrict bias,
                                               const float* __restrict x, std::size_t cols,
                                               std::size_t nb, std::size_t rows,
                                               float* __restrict y, std::size_t w) {
  const std::size_t width = W > 0 ? W : w;
  float acc[kRows][kLanes];
  for (std::size_t r = 0; r < kRows; ++r) {
    const float b0 = bias != nullptr && r < rows ? bias[r] : 0.0F;
#pragma omp simd
    for (std::size_t j = 0; j < width; ++j) acc[r][j] = b0;
  }
  for (std::size_t k = 0; k < cols; ++k) {
    const float* __restrict xk = x + k * nb;
    const float* __restrict pk = p + k * kRows;
    for (std::size_t r = 0; r < kRows; ++r) {
      const float a = pk[r];
#pragma omp simd
      for (std::size_t j = 0; j < width; ++j) acc[r][j] += a * xk[j];
    }
  }
  for (std::size_t r = 0; r < rows; ++r) {
    float* __restrict yr = y + r * nb;
#pragma omp simd
    for (std::size_t j = 0; j < width; ++j) yr[j] = acc[r][j];
  }
}

}  // namespace

std::size_t dense_packed_size(int rows, int cols) {
  return blocks(rows) * kRows * static_cast<std::size_t>(cols);
}

void pack_dense_rows(const float* m, int rows, int cols, std::ptrdiff_t row_stride,
                     std::ptrdiff_t col_stride, float* packed) {
  const auto nc = static_cast<std::size_t>(cols);
  std::fill(packed, packed + dense_packed_size(rows, cols), 0.0F);
  for (int i = 0; i < rows; ++i) {
    float* block = packed + static_cast<std::size_t>(i) / kRows * kRows * nc +
                   static_cast<std::size_t>(i) % kRows;
    const float* row = m + i * row_stride;
    for (std::size_t k = 0; k < nc; ++k) {
      block[k * kRows] = row[static_cast<std::ptrdiff_t>(k) * col_stride];
    }
  }
}

ANIMRT_VECTOR_CLONES
void dense_batch_inner(const float* packed, const float* bias, const float* x, int rows, int cols,
                       int batch, float* y, int first_block, int last_block) {
  const auto nc = static_cast<std::size_t>(cols), nb = static_cast<std::size_t>(batch);
  const auto nr = static_cast<std::size_t>(rows);
  for (auto blk = static_cast<std::size_t>(first_block); blk < static_cast<std::size_t>(last_block);
       ++blk) {
    const std::size_t row0 = blk * kRows;
    const std::size_t in_block = std::min(kRows, nr - row0);
    const float* p = packed + blk * kRows * nc;
    const float* b = bias != nullptr ? bias + row0 : nullptr;
    float* yb = y + row0 * nb;
    std::size_t j = 0;
    for (; j + kLanes <= nb; j += kLanes) {
      block_chunk<kLanes>(p, b, x + j, nc, nb, in_block, yb + j, kLanes);
    }
    if (j < nb) block_chunk<0>(p, b, x + j, nc, nb, in_block, yb + j, nb - j);
  }
}

}  // namespace animrt::seqnet
