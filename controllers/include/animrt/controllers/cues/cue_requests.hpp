#pragma once
// How triggers (OSC, the dashboard, Art-Net: each on its own thread) reach
// the cue player in the cycle. A cue request is a state, "play cue N", like
// a steering command: the newest wins, and one posted while another waits
// replaces it (counted as superseded, never lost silently). Any number of
// writer threads; the one reader is the cycle. Lock-free, nothing allocates.

#include <atomic>
#include <cstdint>
#include <cstring>

namespace animrt {

class CueRequests {
 public:
  // Any thread. A cue also ends a pause: what is asked for plays.
  // `at_s` > 0 asks for it from that time into the cue (a timecode that
  // re-synced into the middle of it).
  void cue(int index, double at_s = 0.0) {
    if (closed_.load(std::memory_order_acquire)) return;
    const std::uint64_t seq = posted_.fetch_add(1, std::memory_order_relaxed) + 1;
    const std::uint32_t seq32 = static_cast<std::uint32_t>(seq);
    // The offset first, tagged with the request it belongs to.
    const float at = at_s > 0.0 ? static_cast<float>(at_s) : 0.0f;
    std::uint32_t bits = 0;
    std::memcpy(&bits, &at, sizeof bits);
    keep_newest(at_, (std::uint64_t{seq32} << 32) | bits);
    keep_newest(request_, (std::uint64_t{seq32} << 32) | static_cast<std::uint32_t>(index));
    paused_.store(false, std::memory_order_release);
  }
  void pause(bool paused) {
    if (!closed_.load(std::memory_order_acquire)) paused_.store(paused, std::memory_order_release);
  }
  // Any thread, once the motion has ended: later requests are neither taken
  // nor counted (the receivers stay open a while after it).
  void close() { closed_.store(true, std::memory_order_release); }

  // The cycle: true and `index` set when a request newer than the last one
  // taken is there; `at_s` its time into the cue.
  bool take(int& index, double& at_s) {
    const std::uint64_t value = request_.load(std::memory_order_acquire);
    const std::uint64_t seq = value >> 32;
    if (seq == taken_seq_) return false;
    taken_seq_ = seq;
    index = static_cast<int>(static_cast<std::uint32_t>(value));
    const std::uint64_t at = at_.load(std::memory_order_acquire);
    at_s = 0.0;
    if ((at >> 32) == seq) {
      float f = 0.0f;
      const auto bits = static_cast<std::uint32_t>(at);
      std::memcpy(&f, &bits, sizeof f);
      at_s = f;
    }
    taken_.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  bool take(int& index) {
    double at_s = 0.0;
    return take(index, at_s);
  }
  bool paused() const { return paused_.load(std::memory_order_acquire); }

  // Any thread: requests posted, and taken by the cycle (the rest were
  // replaced by a newer one before the cycle came round).
  std::uint64_t posted() const { return posted_.load(std::memory_order_relaxed); }
  std::uint64_t taken() const { return taken_.load(std::memory_order_relaxed); }

 private:
  // Keep the newest by sequence: a slower writer never undoes a newer one.
  static void keep_newest(std::atomic<std::uint64_t>& word, std::uint64_t value) {
    std::uint64_t current = word.load(std::memory_order_relaxed);
    while ((current >> 32) < (value >> 32) &&
           !word.compare_exchange_weak(current, value, std::memory_order_release,
                                       std::memory_order_relaxed)) {
    }
  }
  // Sequence (low 32 bits of the count) in the high word, cue in the low;
  // the same sequence over the bits of the request's time into the cue.
  std::atomic<std::uint64_t> request_{0};
  std::atomic<std::uint64_t> at_{0};
  std::atomic<std::uint64_t> posted_{0};
  std::atomic<std::uint64_t> taken_{0};
  std::atomic<bool> paused_{false};
  std::atomic<bool> closed_{false};
  std::uint64_t taken_seq_ = 0;  // the reader's own
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free);
};

}  // namespace animrt
