#pragma once
// How triggers (OSC, the dashboard, Art-Net: each on its own thread) reach
// the cue player in the cycle. A cue request is a state, "play cue N", like
// a steering command: the newest wins, and one posted while another waits
// replaces it (counted as superseded, never lost silently). Any number of
// writer threads; the one reader is the cycle. Lock-free, nothing allocates.

#include <atomic>
#include <cstdint>

namespace animrt {

class CueRequests {
 public:
  // Any thread. A cue also ends a pause: what is asked for plays.
  void cue(int index) {
    const std::uint64_t seq = posted_.fetch_add(1, std::memory_order_relaxed) + 1;
    const std::uint64_t value = (seq << 32) | static_cast<std::uint32_t>(index);
    std::uint64_t current = request_.load(std::memory_order_relaxed);
    // Keep the newest by sequence: a slower writer never undoes a newer one.
    while ((current >> 32) < (seq & 0xffffffffu) &&
           !request_.compare_exchange_weak(current, value, std::memory_order_release,
                                           std::memory_order_relaxed)) {
    }
    paused_.store(false, std::memory_order_release);
  }
  void pause(bool paused) { paused_.store(paused, std::memory_order_release); }

  // The cycle: true and `index` set when a request newer than the last one
  // taken is there.
  bool take(int& index) {
    const std::uint64_t value = request_.load(std::memory_order_acquire);
    const std::uint64_t seq = value >> 32;
    if (seq == taken_seq_) return false;
    taken_seq_ = seq;
    index = static_cast<int>(static_cast<std::uint32_t>(value));
    taken_.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  bool paused() const { return paused_.load(std::memory_order_acquire); }

  // Any thread: requests posted, and taken by the cycle (the rest were
  // replaced by a newer one before the cycle came round).
  std::uint64_t posted() const { return posted_.load(std::memory_order_relaxed); }
  std::uint64_t taken() const { return taken_.load(std::memory_order_relaxed); }

 private:
  // Sequence (low 32 bits of the count) in the high word, cue in the low.
  std::atomic<std::uint64_t> request_{0};
  std::atomic<std::uint64_t> posted_{0};
  std::atomic<std::uint64_t> taken_{0};
  std::atomic<bool> paused_{false};
  std::uint64_t taken_seq_ = 0;  // the reader's own
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free);
};

}  // namespace animrt
