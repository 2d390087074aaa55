#pragma once
// What a DMX receiver does with every frame output for its universe,
// whichever protocol carried it (Art-Net, sACN): count it, hand all its
// channels to the frame handler (joints driven by channels), and report the
// cue channel's value when it changes. Frames come from one receiving thread
// at a time.

#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <utility>

namespace animrt {

class DmxChannelWatch {
 public:
  // Called with the cue channel's new value when it changes.
  using Handler = std::function<void(int value)>;
  // Called with every frame of the universe (all its channels).
  using FrameHandler = std::function<void(std::span<const std::uint8_t> data)>;

  // `channel` 1-512; 0: no cue channel (frames only).
  DmxChannelWatch(int channel, Handler handler, FrameHandler frames)
      : channel_(channel), handler_(std::move(handler)), frame_handler_(std::move(frames)) {}

  void take(std::span<const std::uint8_t> data) {
    frames_.fetch_add(1);
    if (frame_handler_) frame_handler_(data);
    // A frame too short to hold the channel leaves it as it was.
    if (channel_ == 0 || static_cast<std::size_t>(channel_) > data.size()) return;
    const int value = data[static_cast<std::size_t>(channel_ - 1)];
    if (value == last_) return;
    last_ = value;
    handler_(value);
  }

  std::uint64_t frames() const { return frames_.load(); }

 private:
  int channel_;
  Handler handler_;
  FrameHandler frame_handler_;
  int last_ = 0;  // the cue channel's value in the last frame
  std::atomic<std::uint64_t> frames_{0};
};

}  // namespace animrt
