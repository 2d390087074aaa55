#include "animrt/learn/seqnet/mesh_conv_kernel.hpp"

#include <algorithm>
#include <cstddef>
#include <numeric>

#include "vector_clones.hpp"

// The batch loops are marked for the vectoriser (-fopenmp-simd): their rows
// never overlap, which the compiler cannot prove by itself.

namespace animrt::seqnet {

RingRows ring_rows(int vertices, const std::vector<std::int64_t>& rows,
                   const std::vector<std::int64_t>& cols, const std::vector<float>& weight) {
  std::vector<std::size_t> order(rows.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return rows[a] != rows[b] ? rows[a] < rows[b] : cols[a] < cols[b];
  });
  RingRows m;
  m.vertices = vertices;
  m.start.assign(static_cast<std::size_t>(vertices) + 1, 0);
  std::int64_t last_row = -1, last_col = -1;
  for (std::size_t k : order) {
    if (rows[k] == last_row && cols[k] == last_col) {
      m.weight.back() += weight[k];
      continue;
    }
    last_row = rows[k];
    last_col = cols[k];
    m.col.push_back(static_cast<std::int32_t>(cols[k]));
    m.weight.push_back(weight[k]);
    m.start[static_cast<std::size_t>(rows[k]) + 1] = static_cast<std::int32_t>(m.col.size());
  }
  // Rows without entries end where the row before them does.
  for (std::size_t i = 1; i < m.start.size(); ++i)
    m.start[i] = std::max(m.start[i], m.start[i - 1]);
  return m;
}

namespace {

constexpr auto kLanes = static_cast<std::size_t>(kConvLanes);

// out (n numbers) = sum_k w_k x[col_k] over one row of m, rows of n numbers.
[[gnu::always_inline]] inline void gather_row(const RingRows& m, int row, const float* __restrict x,
                                              std::size_t n, float* __restrict out) {
  std::fill(out, out + n, 0.0F);
  for (std::int32_t k = m.start[static_cast<std::size_t>(row)];
       k < m.start[static_cast<std::size_t>(row) + 1]; ++k) {
    const float w = m.weight[static_cast<std::size_t>(k)];
    const float* __restrict src =
        x + static_cast<std::size_t>(m.col[static_cast<std::size_t>(k)]) * n;
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) out[i] += w * src[i];
  }
}

// The batch runs in chunks of kLanes entries: a full chunk has a width
// known at compile time (W = kLanes), so its sums stay in vector
// registers; the last, narrower chunk of an odd batch runs with W = 0 (the
// width `w` at run time).
template <std::size_t W>
[[gnu::always_inline]] inline void forward_chunk(const ConvShape& s, const float* __restrict xv,
                                                 const float* __restrict r,
                                                 const float* __restrict w_self,
                                                 const float* __restrict w_ring,
                                                 const float* __restrict bias, float* __restrict yv,
                                                 std::size_t w) {
  const std::size_t width = W > 0 ? W : w;
  const auto nb = static_cast<std::size_t>(s.batch);
  const auto in = static_cast<std::size_t>(s.in), out = static_cast<std::size_t>(s.out);
  for (std::size_t o = 0; o < out; ++o) {
    float acc[kLanes];
#pragma omp simd
    for (std::size_t j = 0; j < width; ++j) acc[j] = bias[o];
    for (std::size_t c = 0; c < in; ++c) {
      const float a = w_self[o * in + c], m = w_ring[o * in + c];
      const float* __restrict xc = xv + c * nb;
      const float* __restrict rc = r + c * nb;
#pragma omp simd
      for (std::size_t j = 0; j < width; ++j) acc[j] += a * xc[j] + m * rc[j];
    }
    float* __restrict yo = yv + o * nb;
#pragma omp simd
    for (std::size_t j = 0; j < width; ++j) yo[j] = acc[j];
  }
}

template <std::size_t W>
[[gnu::always_inline]] inline void backward_chunk(
    const ConvShape& s, const float* __restrict xv, const float* __restrict rv,
    const float* __restrict yv, const float* __restrict gy, const float* __restrict w_self,
    const float* __restrict w_ring, float* __restrict gx, float* __restrict tv,
    float* __restrict acc_self, float* __restrict acc_ring, float* __restrict acc_bias,
    float* __restrict g, std::size_t w) {
  const std::size_t width = W > 0 ? W : w;
  const auto nb = static_cast<std::size_t>(s.batch);
  const auto in = static_cast<std::size_t>(s.in), out = static_cast<std::size_t>(s.out);
  // g: this chunk's output gradient, [out, kLanes].
  for (std::size_t o = 0; o < out; ++o) {
    float* __restrict go = g + o * kLanes;
    const float* __restrict gyo = gy + o * nb;
    if (yv != nullptr) {
      const float* __restrict yo = yv + o * nb;
#pragma omp simd
      for (std::size_t j = 0; j < width; ++j) go[j] = gyo[j] * (1.0F - yo[j] * yo[j]);
    } else {
#pragma omp simd
      for (std::size_t j = 0; j < width; ++j) go[j] = gyo[j];
    }
    float* __restrict ab = acc_bias + o * kLanes;
#pragma omp simd
    for (std::size_t j = 0; j < width; ++j) ab[j] += go[j];
  }
  for (std::size_t c = 0; c < in; ++c) {
    float to_x[kLanes], to_ring[kLanes];
#pragma omp simd
    for (std::size_t j = 0; j < width; ++j) to_x[j] = to_ring[j] = 0.0F;
    for (std::size_t o = 0; o < out; ++o) {
      const float a = w_self[o * in + c], m = w_ring[o * in + c];
      const float* __restrict go = g + o * kLanes;
#pragma omp simd
      for (std::size_t j = 0; j < width; ++j) {
        to_x[j] += a * go[j];
        to_ring[j] += m * go[j];
      }
    }
    float* __restrict gxc = gx + c * nb;
    float* __restrict tc = tv + c * nb;
#pragma omp simd
    for (std::size_t j = 0; j < width; ++j) {
      gxc[j] = to_x[j];
      tc[j] = to_ring[j];
    }
  }
  for (std::size_t o = 0; o < out; ++o) {
    const float* __restrict go = g + o * kLanes;
    for (std::size_t c = 0; c < in; ++c) {
      float* __restrict as = acc_self + (o * in + c) * kLanes;
      float* __restrict ar = acc_ring + (o * in + c) * kLanes;
      const float* __restrict xc = xv + c * nb;
      const float* __restrict rc = rv + c * nb;
#pragma omp simd
      for (std::size_t j = 0; j < width; ++j) {
        as[j] += go[j] * xc[j];
        ar[j] += go[j] * rc[j];
      }
    }
  }
}

}  // namespace

ANIMRT_VECTOR_CLONES
void mesh_conv_forward(const ConvShape& s, const RingRows& m, const float* x, const float* w_self,
                       const float* w_ring, const float* bias, float* ring, float* y, int first,
                       int last) {
  const auto nb = static_cast<std::size_t>(s.batch);
  const auto in = static_cast<std::size_t>(s.in), out = static_cast<std::size_t>(s.out);
  for (int v = first; v < last; ++v) {
    const auto vi = static_cast<std::size_t>(v);
    float* r = ring + vi * in * nb;
    gather_row(m, v, x, in * nb, r);
    const float* xv = x + vi * in * nb;
    float* yv = y + vi * out * nb;
    std::size_t b = 0;
    for (; b + kLanes <= nb; b += kLanes) {
      forward_chunk<kLanes>(s, xv + b, r + b, w_self, w_ring, bias, yv + b, kLanes);
    }
    if (b < nb) forward_chunk<0>(s, xv + b, r + b, w_self, w_ring, bias, yv + b, nb - b);
  }
}

ANIMRT_VECTOR_CLONES
void mesh_conv_backward_local(const ConvShape& s, const float* x, const float* ring,
                              const float* squashed, const float* grad_y, const float* w_self,
                              const float* w_ring, float* grad_x, float* through, float* acc_self,
                              float* acc_ring, float* acc_bias, int first, int last) {
  const auto nb = static_cast<std::size_t>(s.batch);
  const auto in = static_cast<std::size_t>(s.in), out = static_cast<std::size_t>(s.out);
  std::vector<float> local(out * kLanes);
  for (int v = first; v < last; ++v) {
    const auto vi = static_cast<std::size_t>(v);
    const std::size_t xo = vi * in * nb, yo = vi * out * nb;
    std::size_t b = 0;
    for (; b + kLanes <= nb; b += kLanes) {
      backward_chunk<kLanes>(s, x + xo + b, ring + xo + b,
                             squashed != nullptr ? squashed + yo + b : nullptr, grad_y + yo + b,
                             w_self, w_ring, grad_x + xo + b, through + xo + b, acc_self, acc_ring,
                             acc_bias, local.data(), kLanes);
    }
    if (b < nb) {
      backward_chunk<0>(s, x + xo + b, ring + xo + b,
                        squashed != nullptr ? squashed + yo + b : nullptr, grad_y + yo + b, w_self,
                        w_ring, grad_x + xo + b, through + xo + b, acc_self, acc_ring, acc_bias,
                        local.data(), nb - b);
    }
  }
}

ANIMRT_VECTOR_CLONES
void mesh_conv_backward_ring(const ConvShape& s, const RingRows& adjoint, const float* through,
                             float* grad_x, int first, int last) {
  const std::size_t n = static_cast<std::size_t>(s.in) * static_cast<std::size_t>(s.batch);
  for (int v = first; v < last; ++v) {
    float* __restrict gx = grad_x + static_cast<std::size_t>(v) * n;
    for (std::int32_t k = adjoint.start[static_cast<std::size_t>(v)];
         k < adjoint.start[static_cast<std::size_t>(v) + 1]; ++k) {
      const float w = adjoint.weight[static_cast<std::size_t>(k)];
      const float* __restrict src =
          through + static_cast<std::size_t>(adjoint.col[static_cast<std::size_t>(k)]) * n;
#pragma omp simd
      for (std::size_t i = 0; i < n; ++i) gx[i] += w * src[i];
    }
  }
}

}  // namespace animrt::seqnet
