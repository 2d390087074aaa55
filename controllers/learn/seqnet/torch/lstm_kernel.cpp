#include "animrt/learn/seqnet/lstm_kernel.hpp"

#include <cmath>
#include <cstddef>

#include "vector_clones.hpp"

namespace animrt::seqnet {

namespace {

float sigmoid(float a) { return 1.0F / (1.0F + std::exp(-a)); }

// tanh(a) = 2 sigmoid(2a) - 1: one exp instead of glibc's slower tanhf
// (the two agree to about 2e-7 absolute).
float tanh_by_sigmoid(float a) { return 2.0F / (1.0F + std::exp(-2.0F * a)) - 1.0F; }

}  // namespace

void lstm_cell_forward(float* gates, const float* c, float* c_next, float* h_next, float* tanh_c,
                       int batch, int hidden) {
  const auto nh = static_cast<std::size_t>(hidden);
  for (std::size_t n = 0; n < static_cast<std::size_t>(batch); ++n) {
    float* __restrict g = gates + n * 4 * nh;
    const float* __restrict cr = c + n * nh;
    float* __restrict cn = c_next + n * nh;
    float* __restrict hn = h_next + n * nh;
    float* __restrict tc = tanh_c + n * nh;
    for (std::size_t j = 0; j < nh; ++j) {
      const float i = sigmoid(g[j]);
      const float f = sigmoid(g[nh + j]);
      const float u = tanh_by_sigmoid(g[2 * nh + j]);
      const float o = sigmoid(g[3 * nh + j]);
      g[j] = i;
      g[nh + j] = f;
      g[2 * nh + j] = u;
      g[3 * nh + j] = o;
      const float next = f * cr[j] + i * u;
      const float t = tanh_by_sigmoid(next);
      cn[j] = next;
      tc[j] = t;
      hn[j] = o * t;
    }
  }
}

ANIMRT_VECTOR_CLONES
void lstm_cell_backward(const float* gates, const float* c, const float* tanh_c, const float* gh_a,
                        const float* gh_b, const float* gc, float* d_gates, float* gc_prev,
                        int batch, int hidden) {
  const auto nh = static_cast<std::size_t>(hidden);
  for (std::size_t n = 0; n < static_cast<std::size_t>(batch); ++n) {
    const float* __restrict g = gates + n * 4 * nh;
    const float* __restrict cr = c + n * nh;
    const float* __restrict tc = tanh_c + n * nh;
    float* __restrict d = d_gates + n * 4 * nh;
    float* __restrict gp = gc_prev + n * nh;
#pragma omp simd
    for (std::size_t j = 0; j < nh; ++j) {
      float dh = 0.0F;
      if (gh_a != nullptr) dh += gh_a[n * nh + j];
      if (gh_b != nullptr) dh += gh_b[n * nh + j];
      const float i = g[j], f = g[nh + j], u = g[2 * nh + j], o = g[3 * nh + j];
      const float t = tc[j];
      const float dc = (gc != nullptr ? gc[n * nh + j] : 0.0F) + dh * o * (1.0F - t * t);
      d[j] = dc * u * i * (1.0F - i);
      d[nh + j] = dc * cr[j] * f * (1.0F - f);
      d[2 * nh + j] = dc * i * (1.0F - u * u);
      d[3 * nh + j] = dh * t * o * (1.0F - o);
      gp[j] = dc * f;
    }
  }
}

}  // namespace animrt::seqnet
