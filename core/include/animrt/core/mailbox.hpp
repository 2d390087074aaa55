#pragma once
// A lock-free mailbox that carries the latest value of a command from one
// writer thread (a dashboard, a herd, a jog handler) to the real-time cycle.
// The writer never waits; the reader never waits, never allocates, and gets
// either the newest complete value or nothing. Older values that were never
// read are overwritten: a command is a state ("walk at 0.2 m/s"), not an event
// queue.
//
// A sequence lock: the writer makes the sequence odd, copies, makes it even.
// The reader copies and retries when the sequence moved or was odd. T must be
// trivially copyable; the payload is copied word by word through relaxed
// atomics, so concurrent access is free of data races.

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace animrt {

template <typename T>
class Mailbox {
  static_assert(std::is_trivially_copyable_v<T>, "a mailbox carries plain values");
  static constexpr std::size_t kWords =
      (sizeof(T) + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t);

 public:
  // Writer side: one writer at a time (callers with several writer threads
  // serialise them outside, e.g. the HTTP handler's own mutex).
  void post(const T& value) {
    std::array<std::uint64_t, kWords> words{};
    std::memcpy(words.data(), &value, sizeof(T));
    const std::uint64_t s = sequence_.load(std::memory_order_relaxed);
    sequence_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(words[i], std::memory_order_relaxed);
    sequence_.store(s + 2, std::memory_order_release);
  }

  // Reader side (the cycle). True and `out` set when a value newer than the
  // last one taken is there. Retries a bounded number of times when a write
  // is in progress, then reports nothing new this cycle.
  bool take(T& out) {
    for (int attempt = 0; attempt < 4; ++attempt) {
      const std::uint64_t s0 = sequence_.load(std::memory_order_acquire);
      if (s0 == taken_) return false;
      if (s0 & 1) continue;
      std::array<std::uint64_t, kWords> words{};
      for (std::size_t i = 0; i < kWords; ++i) words[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (sequence_.load(std::memory_order_relaxed) != s0) continue;
      std::memcpy(static_cast<void*>(&out), words.data(), sizeof(T));
      taken_ = s0;
      return true;
    }
    return false;
  }

 private:
  std::atomic<std::uint64_t> sequence_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
  std::uint64_t taken_ = 0;  // reader's own: sequence of the last value taken
};

}  // namespace animrt
