#include "animrt/runtime/loop_stats.hpp"

#include <algorithm>
#include <cmath>

namespace animrt {

void MicrosHistogram::add(double seconds) {
  const double us = std::max(0.0, seconds * 1e6);
  const std::size_t bin = std::min(static_cast<std::size_t>(std::llround(us)), bins_.size() - 1);
  ++bins_[bin];
  ++count_;
  sum_ += seconds;
  max_ = std::max(max_, seconds);
}

double MicrosHistogram::quantile(double q) const {
  if (count_ == 0) return 0.0;
  const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_)));
  std::uint64_t seen = 0;
  for (std::size_t bin = 0; bin < bins_.size(); ++bin) {
    seen += bins_[bin];
    if (seen >= std::max<std::uint64_t>(rank, 1)) {
      return bin + 1 == bins_.size() ? max_ : static_cast<double>(bin) * 1e-6;
    }
  }
  return max_;
}

}  // namespace animrt
