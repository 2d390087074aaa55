#pragma once
// The slots behind emergency_torque_off(): static storage, so a handler that
// runs while a run is being torn down never touches freed memory. A bus I/O
// thread claims one for its lifetime and waits on the slot's wake word, so
// the handler can wake it without a pointer into the thread's object.

#include <atomic>
#include <cstdint>

namespace animrt {

struct EmergencySlot {
  std::atomic<std::uint32_t> claimed{0};
  std::atomic<std::uint32_t> wake{0};     // the I/O thread's wake futex word
  std::atomic<std::uint32_t> request{0};  // 1: switch the bus off and stop
  std::atomic<std::uint32_t> done{0};     // 1: switched off
};

// A free slot, reset, or nullptr when every slot is taken (the bus then runs
// without the emergency path).
EmergencySlot* claim_emergency_slot();
void release_emergency_slot(EmergencySlot* slot);
// The slot's thread has switched its bus off; wakes the waiting handler.
void report_emergency_done(EmergencySlot& slot);
// Marks the calling thread as the one serving `slot` (a handler running on
// that thread does not wait for itself).
void set_thread_emergency_slot(EmergencySlot* slot);

}  // namespace animrt
