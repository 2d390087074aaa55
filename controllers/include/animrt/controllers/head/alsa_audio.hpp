#pragma once
// Blocking ALSA playback and capture of mono float audio, for the head's
// worker thread (never the real-time cycle).

#include <memory>
#include <span>
#include <string>

namespace animrt::head {

class AlsaPlayback {
 public:
  // Throws DeviceError when the device cannot be opened or configured.
  AlsaPlayback(const std::string& device, int sample_rate);
  ~AlsaPlayback();
  AlsaPlayback(const AlsaPlayback&) = delete;
  AlsaPlayback& operator=(const AlsaPlayback&) = delete;
  void write(std::span<const float> samples);  // blocks; recovers from underruns

 private:
  void* pcm_ = nullptr;
};

class AlsaCapture {
 public:
  AlsaCapture(const std::string& device, int sample_rate);
  ~AlsaCapture();
  AlsaCapture(const AlsaCapture&) = delete;
  AlsaCapture& operator=(const AlsaCapture&) = delete;
  // Fills `out` (blocks until it is full); recovers from overruns.
  void read(std::span<float> out);

 private:
  void* pcm_ = nullptr;
};

// True when `device` can be opened for playback (e.g. "default").
bool alsa_playback_available(const std::string& device);

}  // namespace animrt::head
