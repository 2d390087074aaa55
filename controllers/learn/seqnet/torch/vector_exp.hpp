#pragma once
// exp(x) for float in plain arithmetic, so that the vectoriser can run it
// in the training step's loops (glibc's expf is a call per number): x =
// n ln 2 + r with |r| <= ln 2 / 2, e^r by a degree-7
// polynomial (Cephes' coefficients), 2^n by the exponent bits. Within
// 8e-8 relative of exp over [-87, 88] (sampled); clamped outside.

#include <bit>
#include <cstdint>

namespace animrt::seqnet {

[[gnu::always_inline]] inline float vector_exp(float x) {
  x = x < -87.3F ? -87.3F : (x > 88.3F ? 88.3F : x);
  // The nearest whole number by adding and taking away 1.5 2^23 (floor
  // would keep GCC from vectorising the loop).
  constexpr float kRound = 12582912.0F;
  const float n = (x * 1.44269504F + kRound) - kRound;
  // ln 2 in two parts: the first exact in float, so x - n ln 2 loses nothing.
  float r = x - n * 0.693359375F;
  r = r - n * -2.12194440e-4F;
  float p = 1.9875691500e-4F;
  p = p * r + 1.3981999507e-3F;
  p = p * r + 8.3334519073e-3F;
  p = p * r + 4.1665795894e-2F;
  p = p * r + 1.6666665459e-1F;
  p = p * r + 5.0000001201e-1F;
  p = p * r * r + r + 1.0F;
  const auto bits = static_cast<std::uint32_t>(static_cast<std::int32_t>(n) + 127) << 23;
  return p * std::bit_cast<float>(bits);
}

[[gnu::always_inline]] inline float vector_sigmoid(float a) {
  return 1.0F / (1.0F + vector_exp(-a));
}

// tanh(a) = 2 sigmoid(2a) - 1, within 1.8e-7 absolute of tanh.
[[gnu::always_inline]] inline float vector_tanh(float a) {
  return 2.0F / (1.0F + vector_exp(-2.0F * a)) - 1.0F;
}

}  // namespace animrt::seqnet
