#include "animrt/learn/seqnet/mesh_conv_kernel.hpp"

#include <algorithm>
#include <cstddef>
#include <cstring>
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

// The training's shape, 9 input channels and the batch in whole vectors,
// runs with a vertex's channels held in vector registers: the loops above
// keep them in memory (their sizes are known only at run time), and their
// loads and stores, not the multiply-adds, took the time. The sums are
// added in the same order as above.
constexpr std::size_t kRegisterIn = 9;

// One chunk of kLanes batch entries.
using Lanes = float __attribute__((vector_size(kLanes * sizeof(float))));

[[gnu::always_inline]] inline Lanes load(const float* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

[[gnu::always_inline]] inline void store(float* p, Lanes v) { std::memcpy(p, &v, sizeof v); }

bool in_registers(const ConvShape& s) {
  return static_cast<std::size_t>(s.in) == kRegisterIn &&
         static_cast<std::size_t>(s.batch) % kLanes == 0;
}

// Forward of one vertex and chunk (offset b into the batch).
[[gnu::always_inline]] inline void forward_registers(const ConvShape& s, const RingRows& m, int v,
                                                     const float* x, const float* w_self,
                                                     const float* w_ring, const float* bias,
                                                     float* ring, float* y, std::size_t b) {
  constexpr std::size_t in = kRegisterIn;
  const auto nb = static_cast<std::size_t>(s.batch), out = static_cast<std::size_t>(s.out);
  const auto vi = static_cast<std::size_t>(v);
  Lanes r[in] = {};
  for (std::int32_t k = m.start[vi]; k < m.start[vi + 1]; ++k) {
    const float w = m.weight[static_cast<std::size_t>(k)];
    const float* src = x + static_cast<std::size_t>(m.col[static_cast<std::size_t>(k)]) * in * nb + b;
    for (std::size_t c = 0; c < in; ++c) r[c] += w * load(src + c * nb);
  }
  Lanes xs[in];
  const float* xv = x + vi * in * nb + b;
  float* rv = ring + vi * in * nb + b;
  for (std::size_t c = 0; c < in; ++c) {
    xs[c] = load(xv + c * nb);
    store(rv + c * nb, r[c]);
  }
  float* yv = y + vi * out * nb + b;
  for (std::size_t o = 0; o < out; ++o) {
    Lanes acc = Lanes{} + bias[o];
    for (std::size_t c = 0; c < in; ++c) acc += w_self[o * in + c] * xs[c] + w_ring[o * in + c] * r[c];
    store(yv + o * nb, acc);
  }
}

// Vertices a backward block takes: their output gradients wait in a
// buffer, [block, out, kLanes], for the weight gradients' pass, which runs
// one output channel at a time with its 2 x 9 sums in registers.
constexpr std::size_t kBlock = 16;

// Backward, first pass, of one chunk over vertices [first, last).
[[gnu::always_inline]] inline void backward_registers(
    const ConvShape& s, const float* x, const float* ring, const float* squashed,
    const float* grad_y, const float* w_self, const float* w_ring, float* grad_x, float* through,
    float* acc_self, float* acc_ring, float* acc_bias, float* g, std::size_t first, std::size_t last,
    std::size_t b) {
  constexpr std::size_t in = kRegisterIn;
  const auto nb = static_cast<std::size_t>(s.batch), out = static_cast<std::size_t>(s.out);
  for (std::size_t v0 = first; v0 < last; v0 += kBlock) {
    const std::size_t v1 = std::min(last, v0 + kBlock);
    for (std::size_t v = v0; v < v1; ++v) {
      Lanes to_x[in] = {}, to_ring[in] = {};
      float* gv = g + (v - v0) * out * kLanes;
      for (std::size_t o = 0; o < out; ++o) {
        const std::size_t at = (v * out + o) * nb + b;
        Lanes go = load(grad_y + at);
        if (squashed != nullptr) {
          const Lanes yo = load(squashed + at);
          go = go * (1.0F - yo * yo);
        }
        store(gv + o * kLanes, go);
        for (std::size_t c = 0; c < in; ++c) {
          to_x[c] += w_self[o * in + c] * go;
          to_ring[c] += w_ring[o * in + c] * go;
        }
      }
      for (std::size_t c = 0; c < in; ++c) {
        store(grad_x + (v * in + c) * nb + b, to_x[c]);
        store(through + (v * in + c) * nb + b, to_ring[c]);
      }
    }
    for (std::size_t o = 0; o < out; ++o) {
      Lanes as[in], ar[in];
      for (std::size_t c = 0; c < in; ++c) {
        as[c] = load(acc_self + (o * in + c) * kLanes);
        ar[c] = load(acc_ring + (o * in + c) * kLanes);
      }
      Lanes ab = load(acc_bias + o * kLanes);
      for (std::size_t v = v0; v < v1; ++v) {
        const Lanes go = load(g + ((v - v0) * out + o) * kLanes);
        ab += go;
        for (std::size_t c = 0; c < in; ++c) {
          as[c] += go * load(x + (v * in + c) * nb + b);
          ar[c] += go * load(ring + (v * in + c) * nb + b);
        }
      }
      for (std::size_t c = 0; c < in; ++c) {
        store(acc_self + (o * in + c) * kLanes, as[c]);
        store(acc_ring + (o * in + c) * kLanes, ar[c]);
      }
      store(acc_bias + o * kLanes, ab);
    }
  }
}

}  // namespace

ANIMRT_VECTOR_CLONES
void mesh_conv_forward(const ConvShape& s, const RingRows& m, const float* x, const float* w_self,
                       const float* w_ring, const float* bias, float* ring, float* y, int first,
                       int last) {
  const auto nb = static_cast<std::size_t>(s.batch);
  if (in_registers(s)) {
    for (int v = first; v < last; ++v) {
      for (std::size_t b = 0; b < nb; b += kLanes) {
        forward_registers(s, m, v, x, w_self, w_ring, bias, ring, y, b);
      }
    }
    return;
  }
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
  if (in_registers(s)) {
    std::vector<float> block(kBlock * out * kLanes);
    for (std::size_t b = 0; b < nb; b += kLanes) {
      backward_registers(s, x, ring, squashed, grad_y, w_self, w_ring, grad_x, through, acc_self,
                         acc_ring, acc_bias, block.data(), static_cast<std::size_t>(first),
                         static_cast<std::size_t>(last), b);
    }
    return;
  }
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
  if (in_registers(s)) {
    const auto nb = static_cast<std::size_t>(s.batch);
    for (int v = first; v < last; ++v) {
      const auto vi = static_cast<std::size_t>(v);
      for (std::size_t b = 0; b < nb; b += kLanes) {
        Lanes sum[kRegisterIn];
        float* gx = grad_x + vi * n + b;
        for (std::size_t c = 0; c < kRegisterIn; ++c) sum[c] = load(gx + c * nb);
        for (std::int32_t k = adjoint.start[vi]; k < adjoint.start[vi + 1]; ++k) {
          const float w = adjoint.weight[static_cast<std::size_t>(k)];
          const float* src =
              through + static_cast<std::size_t>(adjoint.col[static_cast<std::size_t>(k)]) * n + b;
          for (std::size_t c = 0; c < kRegisterIn; ++c) sum[c] += w * load(src + c * nb);
        }
        for (std::size_t c = 0; c < kRegisterIn; ++c) store(gx + c * nb, sum[c]);
      }
    }
    return;
  }
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
