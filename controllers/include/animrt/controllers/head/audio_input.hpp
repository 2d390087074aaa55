#pragma once
// A live sound source, clocked as a capture device is: read() returns a
// block once its last sample has been captured, so the source's own sample
// clock paces whoever reads it (the head's worker thread, never the cycle).
//
// Two kinds, chosen by the `capture` key of a head motion:
//   an ALSA capture device name ("default", "hw:1,0", ...): the sound card;
//   "pipe:PATH": signed 16-bit little-endian mono PCM at the model's sample
//     rate from a FIFO, read as it is written (a regular file is read at once). Its writer is
//     the device: fed at real time it stands in for a microphone on a
//     machine without a sound card, and the timing the reader sees is the
//     writer's.

#include <atomic>
#include <memory>
#include <span>
#include <string>

namespace animrt::head {

class AudioInput {
 public:
  virtual ~AudioInput() = default;
  // Fills `out` with the next samples, blocking until they have arrived;
  // false when the source has ended (the pipe's writer closed it).
  virtual bool read(std::span<float> out) = 0;
};

inline constexpr const char* kPipeCapturePrefix = "pipe:";

// Opens `spec` (see above) at `sample_rate`; DeviceError when it cannot be
// opened. A read waiting on a silent pipe gives up (false) once `stop` is
// set (checked every 50 ms); an ALSA read returns within a period anyway.
std::unique_ptr<AudioInput> open_audio_input(const std::string& spec, int sample_rate,
                                             const std::atomic<bool>* stop = nullptr);

}  // namespace animrt::head
