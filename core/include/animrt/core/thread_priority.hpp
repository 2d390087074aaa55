#pragma once
// Real-time scheduling for a thread that another one depends on in time (a
// simulated device's answers bound the loop's bus reads): SCHED_FIFO when
// the system permits it; its absence is reported, never fatal.

#include <string>
#include <thread>

namespace animrt {

// Puts `thread` (running) at SCHED_FIFO `priority`. "" when done, otherwise
// why not (e.g. "SCHED_FIFO 78 not permitted (Operation not permitted)").
std::string set_fifo_priority(std::thread& thread, int priority);

}  // namespace animrt
