#include "animrt/learn/seqnet/train_kernel.hpp"

#include <cmath>

#include "vector_clones.hpp"

namespace animrt::seqnet {

ANIMRT_VECTOR_CLONES
void chain_loss_sums(const float* frames, const float* truth, const float* weight, int n,
                     int batch, int dims, double* recon, double* bidir) {
  const auto row = static_cast<std::size_t>(dims);
  const auto frame = static_cast<std::size_t>(batch) * row;
  const auto steps = static_cast<std::size_t>(n);
  double r = 0.0, b = 0.0;
  for (std::size_t t = 0; t < steps; ++t) {
    const std::size_t u = steps - 1 - t;
    double rt = 0.0, bt = 0.0;
    // Unweighted, a frame is one run of B x D numbers; weighted, B rows of D.
    const std::size_t rows = weight ? static_cast<std::size_t>(batch) : 1;
    const std::size_t len = weight ? row : frame;
    for (std::size_t j = 0; j < rows; ++j) {
      const float* __restrict ff = frames + 2 * t * frame + j * len;
      const float* __restrict fb = ff + frame;
      const float* __restrict fb_u = frames + (2 * u + 1) * frame + j * len;
      const float* __restrict xt = truth + t * frame + j * len;
      const float* __restrict xu = truth + u * frame + j * len;
      if (weight) {
        const float* __restrict w = weight;
#pragma omp simd reduction(+ : rt, bt)
        for (std::size_t k = 0; k < len; ++k) {
          const double ef = ff[k] - xt[k], eb = fb[k] - xu[k], ed = ff[k] - fb_u[k];
          rt += w[k] * (ef * ef + eb * eb);
          bt += w[k] * (ed * ed);
        }
      } else {
#pragma omp simd reduction(+ : rt, bt)
        for (std::size_t k = 0; k < len; ++k) {
          const double ef = ff[k] - xt[k], eb = fb[k] - xu[k], ed = ff[k] - fb_u[k];
          rt += ef * ef + eb * eb;
          bt += ed * ed;
        }
      }
    }
    r += rt / static_cast<double>(frame);
    b += bt / static_cast<double>(frame);
  }
  *recon = r;
  *bidir = b;
}

ANIMRT_VECTOR_CLONES
void chain_losses_backward(const float* frames, const float* truth, const float* weight, int n,
                           int batch, int dims, float g_recon, float g_bidir, float* d_frames) {
  const auto row = static_cast<std::size_t>(dims);
  const auto frame = static_cast<std::size_t>(batch) * row;
  const auto steps = static_cast<std::size_t>(n);
  // d/de of mean w e^2 is 2 w e / (B D).
  const float scale = 2.0F / static_cast<float>(frame);
  const float sr = scale * g_recon, sb = scale * g_bidir;
  const std::size_t rows = weight ? static_cast<std::size_t>(batch) : 1;
  const std::size_t len = weight ? row : frame;
  for (std::size_t t = 0; t < steps; ++t) {
    const std::size_t u = steps - 1 - t;
    for (std::size_t j = 0; j < rows; ++j) {
      const float* __restrict ff = frames + 2 * t * frame + j * len;
      const float* __restrict fb = ff + frame;
      const float* __restrict ff_u = frames + 2 * u * frame + j * len;
      const float* __restrict fb_u = ff_u + frame;
      const float* __restrict xt = truth + t * frame + j * len;
      const float* __restrict xu = truth + u * frame + j * len;
      float* __restrict df = d_frames + 2 * t * frame + j * len;
      float* __restrict db = df + frame;
      if (weight) {
        const float* __restrict w = weight;
#pragma omp simd
        for (std::size_t k = 0; k < len; ++k) {
          df[k] = w[k] * (sr * (ff[k] - xt[k]) + sb * (ff[k] - fb_u[k]));
          db[k] = w[k] * (sr * (fb[k] - xu[k]) + sb * (fb[k] - ff_u[k]));
        }
      } else {
#pragma omp simd
        for (std::size_t k = 0; k < len; ++k) {
          df[k] = sr * (ff[k] - xt[k]) + sb * (ff[k] - fb_u[k]);
          db[k] = sr * (fb[k] - xu[k]) + sb * (fb[k] - ff_u[k]);
        }
      }
    }
  }
}

ANIMRT_VECTOR_CLONES
void adam_update(float* p, float* g, float* m, float* v, std::size_t count,
                 const AdamConstants& k) {
  float* __restrict pp = p;
  float* __restrict gp = g;
  float* __restrict mp = m;
  float* __restrict vp = v;
  const float b1 = k.b1, a1 = k.one_b1, b2 = k.b2, a2 = k.one_b2, c1 = k.c1, c2 = k.c2, eps = k.eps,
              step = k.minus_lr;
#pragma omp simd
  for (std::size_t i = 0; i < count; ++i) {
    const float gi = gp[i];
    const float mi = mp[i] * b1 + a1 * gi;
    const float vi = vp[i] * b2 + a2 * gi * gi;
    mp[i] = mi;
    vp[i] = vi;
    pp[i] = pp[i] + step * (mi / c1) / (std::sqrt(vi / c2) + eps);
    gp[i] = 0.0F;
  }
}

}  // namespace animrt::seqnet
