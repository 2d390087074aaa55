#include "sound_track_recorder.hpp"

#include <sndfile.h>
#include <time.h>

#include <cstdio>
#include <exception>
#include <stdexcept>
#include <vector>

#include "animrt/controllers/head/audio_input.hpp"
#include "animrt/core/error.hpp"

namespace animrt::cli {

struct SoundTrackRecorder::Impl {
  std::atomic<bool> stop{false};  // before the capture, which watches it
  std::unique_ptr<head::AudioInput> capture;
  int rate;
  std::string path;
  SNDFILE* file = nullptr;
  std::thread thread;
  double first_sample_s = 0.0;
  std::exception_ptr failure;
  bool finished = false;

  Impl(const std::string& device, int sample_rate, std::string out)
      : capture(head::open_audio_input(device, sample_rate, &stop)),
        rate(sample_rate),
        path(std::move(out)) {
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = 1;
    info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
    file = sf_open(path.c_str(), SFM_WRITE, &info);
    if (file == nullptr) {
      throw std::runtime_error("cannot write the sound track " + quote_path(path) + ": " +
                               sf_strerror(nullptr));
    }
    // Samples in 16-bit units, so the captured 16-bit samples are written
    // exactly (a full-scale 1.0 clips to 32767).
    sf_command(file, SFC_SET_NORM_FLOAT, nullptr, SF_FALSE);
    sf_command(file, SFC_SET_CLIPPING, nullptr, SF_TRUE);
  }

  void run() {
    std::vector<float> block(static_cast<std::size_t>(rate / 100));  // 10 ms
    try {
      bool first = true;
      double frames = 0.0;
      while (!stop.load()) {
        if (!capture->read(block)) break;  // the pipe's writer closed it: the track ends
        for (float& v : block) v *= 32768.0f;
        timespec now{};
        clock_gettime(CLOCK_MONOTONIC, &now);
        const double now_s = static_cast<double>(now.tv_sec) + now.tv_nsec * 1e-9;
        if (first) {
          // The block's first sample was taken one block before it arrived.
          first_sample_s = now_s - static_cast<double>(block.size()) / rate;
          first = false;
        }
        frames += static_cast<double>(block.size());
        // A device that is not paced by a clock (ALSA's null) would fill the disk.
        if (frames > (now_s - first_sample_s + 1.0) * rate) {
          throw DeviceError(
              "the sound track's capture device delivers faster than real time: "
              "not a microphone");
        }
        if (sf_writef_float(file, block.data(), static_cast<sf_count_t>(block.size())) !=
            static_cast<sf_count_t>(block.size())) {
          throw std::runtime_error("cannot write the sound track " + quote_path(path));
        }
      }
    } catch (...) {
      failure = std::current_exception();
    }
  }
};

SoundTrackRecorder::SoundTrackRecorder(const std::string& device, int sample_rate, std::string path)
    : impl_(std::make_unique<Impl>(device, sample_rate, std::move(path))) {}

SoundTrackRecorder::~SoundTrackRecorder() {
  impl_->stop = true;
  if (impl_->thread.joinable()) impl_->thread.join();
  if (impl_->file != nullptr) sf_close(impl_->file);
  if (!impl_->finished) std::remove(impl_->path.c_str());
}

void SoundTrackRecorder::start() {
  impl_->thread = std::thread([this] { impl_->run(); });
}

double SoundTrackRecorder::finish() {
  impl_->stop = true;
  if (impl_->thread.joinable()) impl_->thread.join();
  const int closed = sf_close(impl_->file);
  impl_->file = nullptr;
  if (impl_->failure) std::rethrow_exception(impl_->failure);
  if (closed != 0)
    throw std::runtime_error("cannot write the sound track " + quote_path(impl_->path));
  impl_->finished = true;
  return impl_->first_sample_s;
}

}  // namespace animrt::cli
