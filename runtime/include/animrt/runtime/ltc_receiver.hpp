#pragma once
// SMPTE LTC timecode from an audio input, decoded with libltc on a thread of
// its own (never the cycle's), chased (ltc_chase.hpp), and the cues bound to
// timecode starts asked for when they are due. The input is an ALSA capture
// device ("alsa:DEVICE") or a sound file read at the pace of the monotonic
// clock, as a capture device delivers it, from begin() on (after its end:
// silence).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "animrt/runtime/ltc_chase.hpp"

namespace animrt {

class LtcReceiver {
 public:
  // The cue to ask for, and the time into it the timecode is at.
  using Handler = std::function<void(int cue, double at_s)>;

  // Opens the input (throws InputError for a bad file, DeviceError for a
  // device that cannot be opened) and starts reading.
  LtcReceiver(const std::string& input, double fps, double freewheel_s,
              std::vector<TimecodeCue> cues, Handler handler);
  ~LtcReceiver();
  LtcReceiver(const LtcReceiver&) = delete;
  LtcReceiver& operator=(const LtcReceiver&) = delete;

  // A file starts playing (the figure's motion has started). Any thread,
  // even the cycle: it only sets a flag.
  void begin() { begun_.store(true, std::memory_order_release); }

  std::uint64_t frames() const { return frames_.load(); }
  std::uint64_t jumps() const { return jumps_.load(); }
  std::uint64_t dropouts() const { return dropouts_.load(); }
  std::uint64_t losses() const { return losses_.load(); }
  // Frames whose time no clock shows (dropped).
  std::uint64_t malformed() const { return malformed_.load(); }
  std::uint64_t cues_asked() const { return asked_.load(); }

 private:
  struct Input;
  void run();
  void decode(const float* samples, std::size_t count);

  std::unique_ptr<Input> input_;
  double fps_;
  LtcChase chase_;
  Handler handler_;
  std::atomic<bool> running_{true};
  std::atomic<bool> begun_{false};
  std::atomic<std::uint64_t> frames_{0}, jumps_{0}, dropouts_{0}, losses_{0}, malformed_{0},
      asked_{0};
  std::thread thread_;
};

}  // namespace animrt
