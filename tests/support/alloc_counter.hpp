#pragma once
// Counts calls of the global operator new per thread (alloc_counter.cpp
// replaces operator new in every test binary), to prove that real-time paths
// do not allocate.

#include <cstdint>

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

}  // namespace animrt::test
