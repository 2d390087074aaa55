// The ALSA output of a show's sound track.

#include <alsa/asoundlib.h>

#include "animrt/controllers/show/show_audio.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

// ALSA prints its own diagnostics on stderr (several lines on a machine
// without a sound card); the caller reports the failure once instead.
void quiet(const char*, int, const char*, int, const char*, ...) {}

class AlsaSink final : public AudioSink {
 public:
  AlsaSink(const std::string& device, int rate) {
    snd_lib_error_set_handler(quiet);
    int err = snd_pcm_open(&pcm_, device.c_str(), SND_PCM_STREAM_PLAYBACK, 0);
    if (err >= 0) {
      // 50 ms of buffer: short enough to stay in step, long enough for a
      // normal-priority thread.
      err = snd_pcm_set_params(pcm_, SND_PCM_FORMAT_FLOAT, SND_PCM_ACCESS_RW_INTERLEAVED, 1,
                               static_cast<unsigned>(rate), 1, 50000);
      if (err < 0) snd_pcm_close(pcm_);
    }
    snd_lib_error_set_handler(nullptr);
    if (err < 0) {
      throw DeviceError("ALSA playback device " + quote(device) + ": " + snd_strerror(err));
    }
  }
  ~AlsaSink() override {
    snd_pcm_drop(pcm_);
    snd_pcm_close(pcm_);
  }
  std::int64_t queued_frames() override {
    snd_pcm_sframes_t delay = 0;
    if (snd_pcm_delay(pcm_, &delay) < 0 || delay < 0) return 0;
    return delay;
  }
  void flush() override {
    snd_pcm_drop(pcm_);
    snd_pcm_prepare(pcm_);
  }
  void write(std::span<const float> mono) override {
    std::size_t done = 0;
    while (done < mono.size()) {
      const snd_pcm_sframes_t n = snd_pcm_writei(pcm_, mono.data() + done, mono.size() - done);
      if (n < 0) {
        // An underrun (the show stalled this thread): start again.
        if (snd_pcm_recover(pcm_, static_cast<int>(n), 1) < 0) return;
        continue;
      }
      done += static_cast<std::size_t>(n);
    }
  }

 private:
  snd_pcm_t* pcm_ = nullptr;
};

}  // namespace

std::unique_ptr<AudioSink> open_alsa_sink(const std::string& device, int rate) {
  return std::make_unique<AlsaSink>(device, rate);
}

}  // namespace animrt
