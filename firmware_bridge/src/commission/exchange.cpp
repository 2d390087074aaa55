#include "exchange.hpp"

#include <algorithm>

namespace animrt::commission::detail {

using Clock = std::chrono::steady_clock;
using std::chrono::microseconds;

microseconds wire_time(std::size_t bytes, int baud) {
  const long long bits = static_cast<long long>(bytes) * 10;
  return microseconds{(bits * 1'000'000 + std::max(baud, 1) - 1) / std::max(baud, 1)};
}

std::vector<std::uint8_t> exchange(ByteTransport& line, std::span<const std::uint8_t> request,
                                   const Wait& wait,
                                   const std::function<bool(std::span<const std::uint8_t>)>& done) {
  std::vector<std::uint8_t> got;
  line.discard_input();
  if (!line.write(request)) return got;
  const auto start = Clock::now();
  const auto end = start + wait.cap;
  auto deadline = std::min(end, start + wait.first);
  std::uint8_t buffer[512];
  for (;;) {
    const auto now = Clock::now();
    if (now >= deadline) break;
    const auto left = std::chrono::ceil<microseconds>(deadline - now);
    const std::size_t n = line.read(buffer, left);
    if (n == 0) {
      if (line.failure() != nullptr) break;
      continue;
    }
    got.insert(got.end(), buffer, buffer + n);
    if (done && done(got)) break;
    deadline = std::min(end, Clock::now() + wait.quiet);
  }
  return got;
}

}  // namespace animrt::commission::detail
