#include "animrt/learn/seqnet/lstm_kernel.hpp"

#include <cstddef>

#include "vector_clones.hpp"
#include "vector_exp.hpp"

namespace animrt::seqnet {

ANIMRT_VECTOR_CLONES
void lstm_cell_forward(float* gates, const float* c, float* c_next, float* h_next, float* tanh_c,
                       int count) {
  const auto n = static_cast<std::size_t>(count);
  float* __restrict gi = gates;
  float* __restrict gf = gates + n;
  float* __restrict gg = gates + 2 * n;
  float* __restrict go = gates + 3 * n;
  const float* __restrict cr = c;
  float* __restrict cn = c_next;
  float* __restrict hn = h_next;
  float* __restrict tc = tanh_c;
#pragma omp simd
  for (std::size_t k = 0; k < n; ++k) {
    const float i = vector_sigmoid(gi[k]);
    const float f = vector_sigmoid(gf[k]);
    const float u = vector_tanh(gg[k]);
    const float o = vector_sigmoid(go[k]);
    gi[k] = i;
    gf[k] = f;
    gg[k] = u;
    go[k] = o;
    const float next = f * cr[k] + i * u;
    const float t = vector_tanh(next);
    cn[k] = next;
    tc[k] = t;
    hn[k] = o * t;
  }
}

namespace {

// h's gradient from one array or the sum of two: TWO known at compile time
// so that the vectorised loop never reads a null `gh_b`.
template <bool TWO>
[[gnu::always_inline]] inline void cell_backward(const float* gates, const float* c,
                                                 const float* tanh_c, const float* gh_a,
                                                 const float* gh_b, const float* gc, float* d_gates,
                                                 float* gc_prev, std::size_t n) {
  const float* __restrict gi = gates;
  const float* __restrict gf = gates + n;
  const float* __restrict gg = gates + 2 * n;
  const float* __restrict go = gates + 3 * n;
  const float* __restrict cr = c;
  const float* __restrict tc = tanh_c;
  const float* __restrict ha = gh_a;
  const float* __restrict hb = gh_b;
  const float* __restrict gcn = gc;
  float* __restrict di = d_gates;
  float* __restrict df = d_gates + n;
  float* __restrict dg = d_gates + 2 * n;
  float* __restrict dout = d_gates + 3 * n;
  float* __restrict gp = gc_prev;
#pragma omp simd
  for (std::size_t k = 0; k < n; ++k) {
    float dh = ha[k];
    if constexpr (TWO) dh += hb[k];
    const float i = gi[k], f = gf[k], u = gg[k], o = go[k];
    const float t = tc[k];
    const float dc = gcn[k] + dh * o * (1.0F - t * t);
    di[k] = dc * u * i * (1.0F - i);
    df[k] = dc * cr[k] * f * (1.0F - f);
    dg[k] = dc * i * (1.0F - u * u);
    dout[k] = dh * t * o * (1.0F - o);
    gp[k] = dc * f;
  }
}

}  // namespace

ANIMRT_VECTOR_CLONES
void lstm_cell_backward(const float* gates, const float* c, const float* tanh_c, const float* gh_a,
                        const float* gh_b, const float* gc, float* d_gates, float* gc_prev,
                        int count) {
  const auto n = static_cast<std::size_t>(count);
  if (gh_b != nullptr) {
    cell_backward<true>(gates, c, tanh_c, gh_a, gh_b, gc, d_gates, gc_prev, n);
  } else {
    cell_backward<false>(gates, c, tanh_c, gh_a, gh_b, gc, d_gates, gc_prev, n);
  }
}

ANIMRT_VECTOR_CLONES
void tanh_in_place(float* y, std::size_t count) {
  float* __restrict v = y;
#pragma omp simd
  for (std::size_t k = 0; k < count; ++k) v[k] = vector_tanh(v[k]);
}

}  // namespace animrt::seqnet
