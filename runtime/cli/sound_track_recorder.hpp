#pragma once
// The microphone recorded beside a puppeteered show: captured on a thread of
// its own (never the loop that reads the joints) straight into a WAV file,
// so a long take does not grow in memory.

#include <atomic>
#include <memory>
#include <string>
#include <thread>

namespace animrt::cli {

class SoundTrackRecorder {
 public:
  // Opens the capture (an ALSA device, or pipe:PATH as a head's `capture`
  // key takes it: s16le mono at `sample_rate`) and the file (DeviceError,
  // or std::runtime_error for a file that cannot be written); nothing runs
  // yet. A pipe whose writer closes it ends the track there.
  SoundTrackRecorder(const std::string& capture, int sample_rate, std::string path);
  ~SoundTrackRecorder();  // stops; a file not finished by finish() is removed
  SoundTrackRecorder(const SoundTrackRecorder&) = delete;
  SoundTrackRecorder& operator=(const SoundTrackRecorder&) = delete;

  void start();
  // Stops and closes the file; the CLOCK_MONOTONIC time (s) of its first
  // sample. Throws what the capture thread met (a device that failed).
  double finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace animrt::cli
