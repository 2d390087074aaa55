#pragma once
// Every catchable signal that would end the process is a stop request: the
// figure ramps home and the run ends as after Ctrl-C. A second one of those
// sent from outside (all but SIGPIPE, SIGXFSZ and SIGXCPU) switches torque
// off at once, as a second Ctrl-C does. SIGPIPE and SIGXFSZ come from the
// process's own writes and repeat with every write, SIGXCPU from a CPU-time
// limit and repeats every second past it, so each stops at most once and
// never cuts torque; a SIGPIPE stops only when it is stdout or stderr whose
// reader left (`animrt run ... | head -1`), not a socket or a telemetry pipe
// (those writes fail with EPIPE and are counted where they happen).

#include <span>

#include "animrt/runtime/run_controls.hpp"

namespace animrt::cli {

struct StopSignal {
  int number;
  const char* name;
  bool counts;  // a second one cuts torque
};

std::span<const StopSignal> stop_signals();

// What a second counted signal does: cut torque (a run: controls.abort), or
// end the process at once by that signal's default action (a command that
// holds no torque and ends its work at a stop: a herd or a search with a
// dashboard, which write their files first).
enum class SecondSignal { cut_torque, end_process };

// Installs the handlers; they write to `controls` (which must outlive the
// process's use of them). Lock-free atomics only.
void install_stop_signals(RunControls& controls, SecondSignal second = SecondSignal::cut_torque);

// For commands that take the signals with sigwait (the view): every stop
// signal that counts, in one set.
void add_counting_stop_signals(sigset_t& set);

}  // namespace animrt::cli
