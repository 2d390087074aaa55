#pragma once
// The search's random numbers: a 64-bit Mersenne twister with our own
// integer and real draws (the std distributions differ between library
// versions), so a run is reproducible from its seed.

#include <cstdint>
#include <random>

namespace animrt::evolve {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  // Uniform in [0, n), n > 0, without modulo bias.
  std::uint64_t below(std::uint64_t n) {
    const std::uint64_t limit = UINT64_MAX - UINT64_MAX % n;
    std::uint64_t x = 0;
    do {
      x = engine_();
    } while (x >= limit);
    return x % n;
  }
  int index(std::size_t n) { return static_cast<int>(below(n)); }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  bool chance(double p) { return uniform() < p; }

 private:
  std::mt19937_64 engine_;
};

}  // namespace animrt::evolve
