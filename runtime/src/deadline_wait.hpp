#pragma once
// Futex wait with an absolute CLOCK_MONOTONIC deadline, so that a wait that
// wakes up early (another bus finished) keeps the same end point.

#include <atomic>
#include <cstdint>

#include "animrt/core/clock.hpp"

namespace animrt {

// Waits while `word` == `expected`, until `deadline` (CLOCK_MONOTONIC, ns);
// deadline < 0 waits without limit. Returns on a wake, a change or the deadline.
void futex_wait_until(std::atomic<std::uint32_t>& word, std::uint32_t expected, Nanos deadline);

}  // namespace animrt
