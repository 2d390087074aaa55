#pragma once
// The byte buffer behind every serial-servo codec's streaming decoder:
// bytes are appended as they arrive, and dropped from the front once a
// packet was taken or the bytes before a header were skipped. Fixed size,
// no allocation.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

namespace animrt::servo {

template <std::size_t N>
class RxBuffer {
 public:
  void reset() { size_ = 0; }
  // Appends bytes; returns how many fitted (the rest must be fed again later).
  std::size_t feed(std::span<const std::uint8_t> bytes) {
    const std::size_t n = std::min(bytes.size(), N - size_);
    if (n > 0) std::memcpy(buffer_ + size_, bytes.data(), n);
    size_ += n;
    return n;
  }
  void drop_front(std::size_t n) {
    if (n >= size_) {
      size_ = 0;
      return;
    }
    std::memmove(buffer_, buffer_ + n, size_ - n);
    size_ -= n;
  }
  // Drops the `n` bytes before a header, counted as stray.
  void skip(std::size_t n) {
    stray_ += n;
    drop_front(n);
  }
  const std::uint8_t* data() const { return buffer_; }
  std::uint8_t operator[](std::size_t i) const { return buffer_[i]; }
  std::size_t size() const { return size_; }
  std::uint64_t stray() const { return stray_; }

 private:
  std::uint8_t buffer_[N]{};
  std::size_t size_ = 0;
  std::uint64_t stray_ = 0;
};

}  // namespace animrt::servo
