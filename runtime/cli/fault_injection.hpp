#pragma once
// Test hooks for the fatal-error path (emergency_stop.hpp), read once at the
// start of `animrt run`; absent (always, outside tests), nothing happens.
//   ANIMRT_TEST_UNCAUGHT_EXCEPTION_AFTER_S=SECONDS: a thread throws an
//     exception nobody catches that many seconds after the run starts, as a
//     bug in a helper thread would.
//   ANIMRT_TEST_BAD_WRITE_AFTER_S=SECONDS: a thread writes to a page it may
//     not write then: a real SIGSEGV, raised by the fault, not sent.
//   ANIMRT_TEST_STALL_LOOP_AFTER_S=SECONDS: the thread that called
//     start_fault_injection (the loop's) stops there for good, as a loop
//     stuck in a driver call would, while every other thread runs on.
//     Called just before the run, on the thread that runs the loop.
//   ANIMRT_TEST_SLOW_EXIT_S=SECONDS: `animrt serve` waits that long after
//     the run, before its summary, as a loaded machine's slow exit would.
//   ANIMRT_TEST_TRANSITION_DELAY_S=SECONDS: `animrt serve`'s learned
//     in-betweens each take at least that long to compute (a slow model).

namespace animrt::cli {

void start_fault_injection();
void slow_exit_for_test();
// The seconds of ANIMRT_TEST_TRANSITION_DELAY_S, 0 when unset.
double transition_delay_for_test();

}  // namespace animrt::cli
