#pragma once
// Futex waits and wakes on a 32-bit atomic: how the loop and the bus I/O
// threads hand work over without a mutex. Waits end at an absolute
// CLOCK_MONOTONIC deadline, so a wait that wakes up early (another bus
// finished) keeps the same end point.

#include <atomic>
#include <cstdint>

#include "animrt/core/clock.hpp"

namespace animrt {

// Waits while `word` == `expected`, until `deadline` (CLOCK_MONOTONIC, ns);
// deadline < 0 waits without limit. Returns on a wake, a change or the deadline.
void futex_wait_until(std::atomic<std::uint32_t>& word, std::uint32_t expected, Nanos deadline);
void futex_wake_all(std::atomic<std::uint32_t>& word);

}  // namespace animrt
