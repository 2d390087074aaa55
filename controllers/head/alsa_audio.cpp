#include "animrt/controllers/head/alsa_audio.hpp"

#include <alsa/asoundlib.h>

#include "animrt/core/error.hpp"

namespace animrt::head {
namespace {

// ALSA prints its own diagnostics on stderr (several lines on a machine
// without a sound card); the caller reports a failure once instead.
void quiet(const char*, int, const char*, int, const char*, ...) {}

int open_quietly(snd_pcm_t** pcm, const std::string& device, snd_pcm_stream_t stream, int mode) {
  snd_lib_error_set_handler(quiet);
  const int err = snd_pcm_open(pcm, device.c_str(), stream, mode);
  snd_lib_error_set_handler(nullptr);
  return err;
}

snd_pcm_t* open_pcm(const std::string& device, int rate, snd_pcm_stream_t stream,
                    unsigned latency_us) {
  snd_pcm_t* pcm = nullptr;
  const char* what = stream == SND_PCM_STREAM_PLAYBACK ? "playback" : "capture";
  int err = open_quietly(&pcm, device, stream, 0);
  if (err < 0) {
    throw DeviceError("ALSA " + std::string(what) + " device " + quote(device) + ": " +
                      snd_strerror(err));
  }
  err = snd_pcm_set_params(pcm, SND_PCM_FORMAT_FLOAT_LE, SND_PCM_ACCESS_RW_INTERLEAVED, 1,
                           static_cast<unsigned>(rate), 1, latency_us);
  if (err < 0) {
    snd_pcm_close(pcm);
    throw DeviceError("ALSA " + std::string(what) + " device " + quote(device) + ": " +
                      snd_strerror(err));
  }
  return pcm;
}

}  // namespace

AlsaPlayback::AlsaPlayback(const std::string& device, int rate)
    : pcm_(open_pcm(device, rate, SND_PCM_STREAM_PLAYBACK, 50000)) {}
AlsaPlayback::~AlsaPlayback() {
  auto* pcm = static_cast<snd_pcm_t*>(pcm_);
  snd_pcm_drain(pcm);
  snd_pcm_close(pcm);
}
void AlsaPlayback::write(std::span<const float> samples) {
  auto* pcm = static_cast<snd_pcm_t*>(pcm_);
  std::size_t done = 0;
  while (done < samples.size()) {
    const snd_pcm_sframes_t n = snd_pcm_writei(pcm, samples.data() + done, samples.size() - done);
    if (n < 0) {
      if (snd_pcm_recover(pcm, static_cast<int>(n), 1) < 0) return;
      continue;
    }
    done += static_cast<std::size_t>(n);
  }
}

// A short capture buffer (periods of a few ms): the jaw waits for each period.
AlsaCapture::AlsaCapture(const std::string& device, int rate)
    : pcm_(open_pcm(device, rate, SND_PCM_STREAM_CAPTURE, 20000)) {}
AlsaCapture::~AlsaCapture() { snd_pcm_close(static_cast<snd_pcm_t*>(pcm_)); }
void AlsaCapture::read(std::span<float> out) {
  auto* pcm = static_cast<snd_pcm_t*>(pcm_);
  std::size_t done = 0;
  while (done < out.size()) {
    const snd_pcm_sframes_t n = snd_pcm_readi(pcm, out.data() + done, out.size() - done);
    if (n < 0) {
      if (snd_pcm_recover(pcm, static_cast<int>(n), 1) < 0)
        throw DeviceError("ALSA capture failed");
      continue;
    }
    done += static_cast<std::size_t>(n);
  }
}

bool alsa_playback_available(const std::string& device) {
  snd_pcm_t* pcm = nullptr;
  if (open_quietly(&pcm, device, SND_PCM_STREAM_PLAYBACK, SND_PCM_NONBLOCK) < 0) return false;
  snd_pcm_close(pcm);
  return true;
}

}  // namespace animrt::head
