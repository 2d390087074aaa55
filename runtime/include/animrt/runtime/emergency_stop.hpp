#pragma once
// Torque off from a process that is dying. A fatal error (an uncaught
// exception, an assertion, a segfault) ends the process without unwinding,
// so the scope guard that switches the buses off at the end of a run never
// runs. What can still run then are the bus I/O threads: each running one
// holds a slot here, and a fatal-error handler asks every slot's thread to
// switch its bus off (the bus's own deactivate()), waits a bounded time for
// them, and lets the process end as it would have (same exit status, same
// core dump). A bus whose own thread is the one that crashed, and a process
// that cannot run at all any more (kill -9, power cut), are left to the
// devices' own watchdogs.

#include <cstdint>

#include "animrt/core/clock.hpp"

namespace animrt {

// How long a fatal-error handler waits for the bus I/O threads.
inline constexpr Nanos kEmergencyWait = 1'000'000'000;

struct EmergencyResult {
  int buses = 0;         // buses whose I/O thread was running
  int switched_off = 0;  // of them, switched off within the wait
};

// Asks every running bus I/O thread to switch its bus off, and waits until
// they have or `wait` has passed. Async-signal-safe (atomics and futex
// calls only); safe to call again (a bus is switched off once).
EmergencyResult emergency_torque_off(Nanos wait = kEmergencyWait);

// Installs the fatal-error handlers: std::terminate, and SIGABRT, SIGSEGV,
// SIGBUS, SIGFPE, SIGILL (on an alternate stack, so a stack overflow is
// caught too). Each calls emergency_torque_off(), writes one line to stderr
// when a bus was running, then ends the process the way it was going to end.
void install_fatal_error_handlers();

}  // namespace animrt
