#pragma once
// Loop timing statistics, gathered without allocation: a microsecond
// histogram, one each for the period between cycle starts, the wake-up
// latency (how late a cycle started against its deadline), the work per
// cycle and every bus's I/O time.

#include <cstdint>
#include <vector>

namespace animrt {

class MicrosHistogram {
 public:
  explicit MicrosHistogram(std::size_t max_us = 200'000) : bins_(max_us + 1, 0) {}
  void add(double seconds);
  std::uint64_t count() const { return count_; }
  // Value (seconds) below which `q` of the samples fall; bin resolution 1 us.
  double quantile(double q) const;
  double max() const { return max_; }
  double mean() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }

 private:
  std::vector<std::uint32_t> bins_;  // last bin collects everything beyond
  std::uint64_t count_ = 0;
  double sum_ = 0.0;
  double max_ = 0.0;
};

}  // namespace animrt
