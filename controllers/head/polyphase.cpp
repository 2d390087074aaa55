// Polyphase windowed-sinc resampling (see polyphase.hpp).

#include "polyphase.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace animrt::head {
namespace {

constexpr int kPolyMaxPhases = 4096;
constexpr int kPolyHalfTaps = 16;  // per side, at a ratio of 1 or more
constexpr double kPolyBeta = 8.6;
constexpr double kPolyPassband = 0.9;  // of the lower Nyquist frequency
constexpr double kPolyPi = 3.14159265358979323846;

// phases x taps coefficients; tap k of phase p weighs input sample
// floor(position) - half + 1 + k for an output at fractional position p / L.
std::vector<float> poly_table(int phases, int half, double cutoff) {
  const int taps = 2 * half;
  std::vector<float> table(static_cast<std::size_t>(phases) * static_cast<std::size_t>(taps));
  const double norm = std::cyl_bessel_i(0.0, kPolyBeta);
  for (int p = 0; p < phases; ++p) {
    const double frac = static_cast<double>(p) / phases;
    double sum = 0.0;
    float* row = &table[static_cast<std::size_t>(p) * static_cast<std::size_t>(taps)];
    for (int k = 0; k < taps; ++k) {
      const double t = static_cast<double>(k - half + 1) - frac;  // input samples from the output
      const double x = 2.0 * cutoff * t;
      const double sinc = std::abs(x) < 1e-12 ? 1.0 : std::sin(kPolyPi * x) / (kPolyPi * x);
      const double r = t / half;
      const double w = std::abs(r) >= 1.0
                           ? 0.0
                           : std::cyl_bessel_i(0.0, kPolyBeta * std::sqrt(1.0 - r * r)) / norm;
      row[k] = static_cast<float>(sinc * w);
      sum += row[k];
    }
    for (int k = 0; k < taps; ++k) row[k] = static_cast<float>(row[k] / sum);  // unity gain
  }
  return table;
}

// Outputs n .. n + kPolyBlock - 1, all inside the input: each sum in the
// same order as one output alone, several at once so that their additions
// overlap instead of waiting on each other.
constexpr int kPolyBlock = 4;
void interior_block(const float* table, int taps, const float* in, std::int64_t n, std::int64_t up,
                    std::int64_t down, int half, float* out) {
  auto row = [&](int j) {
    return table + static_cast<std::size_t>(((n + j) * down) % up) * static_cast<std::size_t>(taps);
  };
  auto at = [&](int j) { return in + static_cast<std::size_t>((n + j) * down / up - half + 1); };
  const float *h0 = row(0), *h1 = row(1), *h2 = row(2), *h3 = row(3);
  const float *x0 = at(0), *x1 = at(1), *x2 = at(2), *x3 = at(3);
  float a0 = 0.0f, a1 = 0.0f, a2 = 0.0f, a3 = 0.0f;
  for (int k = 0; k < taps; ++k) {
    a0 += h0[k] * x0[k];
    a1 += h1[k] * x1[k];
    a2 += h2[k] * x2[k];
    a3 += h3[k] * x3[k];
  }
  out[0] = a0;
  out[1] = a1;
  out[2] = a2;
  out[3] = a3;
}

}  // namespace

bool resample_polyphase(std::span<const float> in, int in_rate, int out_rate,
                        std::vector<float>& out) {
  const int g = std::gcd(in_rate, out_rate);
  const std::int64_t up = out_rate / g, down = in_rate / g;  // L, M
  if (up > kPolyMaxPhases || down > kPolyMaxPhases * 16) return false;
  // Downsampling narrows the band and widens the filter by the same ratio.
  const double shrink = std::min(1.0, static_cast<double>(up) / static_cast<double>(down));
  const int half = static_cast<int>(std::ceil(kPolyHalfTaps / shrink));
  const int taps = 2 * half;
  const std::vector<float> table =
      poly_table(static_cast<int>(up), half, 0.5 * kPolyPassband * shrink);
  const auto n_in = static_cast<std::int64_t>(in.size());
  const std::int64_t n_out = n_in * up / down;
  out.assign(static_cast<std::size_t>(n_out), 0.0f);
  for (std::int64_t n = 0; n < n_out; ++n) {
    const std::int64_t pos = n * down;
    const std::int64_t first = pos / up - half + 1;
    const float* h = &table[static_cast<std::size_t>(pos % up) * static_cast<std::size_t>(taps)];
    float acc = 0.0f;
    if (first >= 0 && n + kPolyBlock <= n_out &&
        (n + kPolyBlock - 1) * down / up - half + 1 + taps <= n_in) {
      interior_block(table.data(), taps, in.data(), n, up, down, half,
                     &out[static_cast<std::size_t>(n)]);
      n += kPolyBlock - 1;
      continue;
    }
    if (first >= 0 && first + taps <= n_in) {
      const float* x = &in[static_cast<std::size_t>(first)];
      for (int k = 0; k < taps; ++k) acc += h[k] * x[k];
    } else {
      for (int k = 0; k < taps; ++k) {
        const std::int64_t i = first + k;
        if (i >= 0 && i < n_in) acc += h[k] * in[static_cast<std::size_t>(i)];
      }
    }
    out[static_cast<std::size_t>(n)] = acc;
  }
  return true;
}

}  // namespace animrt::head
