#pragma once
// Real-time privileges for the loop thread: SCHED_FIFO and locked memory
// when the system permits. Their absence is reported, never fatal.

#include <string>

namespace animrt {

struct RealtimeStatus {
  bool sched_fifo = false;
  int priority = 0;
  std::string sched_note;  // why not, when not
  bool memory_locked = false;
  std::string mlock_note;
};

// Requests SCHED_FIFO at `priority` for the calling thread and mlockall().
RealtimeStatus request_realtime(int priority);
// Returns the calling thread to SCHED_OTHER (after the loop).
void release_realtime();

}  // namespace animrt
