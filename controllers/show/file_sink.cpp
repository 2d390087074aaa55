// A sound output that writes to a file what a sound card would play: raw
// 16-bit little-endian mono at the track's rate, in real time. It stands in
// for a sound card (tests, a machine without one): it keeps at most 50 ms
// queued as a card's buffer does, what a flush drops is cut from the file,
// and an output left without samples starts again at the next write (an
// underrun), so the file holds exactly what a listener would have heard.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include "animrt/controllers/show/show_audio.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

class FileSink final : public AudioSink {
 public:
  FileSink(std::FILE* file, int rate) : file_(file), rate_(rate), capacity_(rate / 20) {}
  ~FileSink() override { std::fclose(file_); }

  std::int64_t queued_frames() override { return written_ - heard(); }

  void write(std::span<const float> mono) override {
    if (written_ - heard() == 0) {  // started, or ran dry: plays from now
      base_ = written_;
      start_ = clock_.now();
    }
    samples_.resize(mono.size());
    for (std::size_t i = 0; i < mono.size(); ++i)
      samples_[i] =
          static_cast<std::int16_t>(std::lround(std::clamp(mono[i], -1.0f, 1.0f) * 32767.0f));
    std::fwrite(samples_.data(), sizeof(std::int16_t), samples_.size(), file_);
    written_ += static_cast<std::int64_t>(mono.size());
    // A card takes no more than its buffer holds: the writer waits.
    while (written_ - heard() > capacity_)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }

  void flush() override {
    const std::int64_t keep = heard();
    std::fflush(file_);
    if (::ftruncate(::fileno(file_), static_cast<off_t>(keep * 2)) == 0) {
      std::fseek(file_, 0, SEEK_END);
      written_ = keep;
    }
  }

 private:
  // Frames played so far (all that was written, if the output ran dry).
  std::int64_t heard() const {
    const double elapsed = to_seconds(clock_.now() - start_);
    const auto due = base_ + static_cast<std::int64_t>(std::floor(elapsed * rate_));
    return std::min(due, written_);
  }

  std::FILE* file_;
  int rate_;
  std::int64_t capacity_;
  MonotonicClock clock_;
  Nanos start_ = 0;
  std::int64_t base_ = 0;     // frames written before the output last (re)started
  std::int64_t written_ = 0;  // frames in the file
  std::vector<std::int16_t> samples_;
};

}  // namespace

std::unique_ptr<AudioSink> open_file_sink(const std::string& path, int rate) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    throw DeviceError("sound output file " + quote_path(path) + ": " + std::strerror(errno));
  }
  return std::make_unique<FileSink>(file, rate);
}

}  // namespace animrt
