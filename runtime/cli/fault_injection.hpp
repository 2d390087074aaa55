#pragma once
// A test hook for the fatal-error path (emergency_stop.hpp): with
// ANIMRT_TEST_UNCAUGHT_EXCEPTION_AFTER_S=SECONDS in the environment, a
// thread of `animrt run` throws an exception nobody catches that many
// seconds after the run starts, as a bug in a helper thread would. Read once,
// at the start; absent (always, outside tests), nothing happens.

namespace animrt::cli {

void start_fault_injection();

}  // namespace animrt::cli
