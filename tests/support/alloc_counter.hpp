#pragma once
// Counts allocations, to prove that real-time paths do not allocate.
//
// Per thread: calls of the global operator new by the calling thread
// (alloc_counter.cpp replaces operator new in every test binary).
//
// Per run (RunAllocationWatch): allocations on every thread a run owns, C and
// C++ alike (malloc, calloc, realloc and the aligned forms are counted too,
// except in AddressSanitizer builds, where the sanitizer owns malloc and only
// operator new is counted).
// Which threads a run owns is decided by lineage, not by name: pthread_create
// is interposed, and a thread started by a run thread is a run thread. The
// watch makes the calling thread (the one that calls Runner::run, i.e. the
// loop thread) a run thread while it lives, so the bus I/O threads and the
// telemetry writer that run() starts are run threads; the simulated devices'
// threads were started earlier by the test (or by the simulators' own
// threads) and are not. The telemetry writer is told apart by the callable
// its std::thread runs (the type name of libstdc++'s thread state names
// animrt::TelemetryWriter, or animrt::McapRecorder for the MCAP recording's)
// and is left out of the count: it writes a file, outside the cycle by design. A run thread that cannot be recognised counts.
// Only allocations made while the window is open count.

#include <cstdint>
#include <string>

namespace animrt::test {

// Allocations made by the calling thread since it started.
std::uint64_t thread_allocations();

// Allocations made by this thread while the counter is alive.
class AllocationCounter {
 public:
  AllocationCounter() : start_(thread_allocations()) {}
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  long count() const { return static_cast<long>(thread_allocations() - start_); }

 private:
  std::uint64_t start_;
};

enum class RunThread : int { loop, bus_io, telemetry_writer, other };
enum class RunPhase : int { start_ramp, motion, stop_ramp };

// One at a time (the counters are process-wide). Construct it on the thread
// that will call Runner::run, after the simulated devices have started.
class RunAllocationWatch {
 public:
  RunAllocationWatch();
  ~RunAllocationWatch();
  RunAllocationWatch(const RunAllocationWatch&) = delete;
  RunAllocationWatch& operator=(const RunAllocationWatch&) = delete;

  // The window; safe from any thread, allocation-free.
  void open();
  void close();
  void set_phase(RunPhase phase);  // what the allocations counted from now are filed under

  bool is_open() const;
  bool was_opened() const;
  // Allocations in the window on run threads, the telemetry writer excluded.
  std::uint64_t counted() const;
  std::uint64_t on(RunThread thread) const;  // the writer's own count included
  std::uint64_t in(RunPhase phase) const;
  // Run threads started while the watch lived, by kind.
  int started(RunThread thread) const;
  // Thread kind, phase and symbolised call stack of the first counted
  // allocations ("" when there were none).
  std::string where() const;
};

}  // namespace animrt::test
