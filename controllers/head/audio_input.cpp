// Live sound sources: an ALSA capture device, or a pipe standing in for one.

#include "animrt/controllers/head/audio_input.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "animrt/controllers/head/alsa_audio.hpp"
#include "animrt/core/error.hpp"

namespace animrt::head {
namespace {

class AlsaInput final : public AudioInput {
 public:
  AlsaInput(const std::string& device, int rate) : capture_(device, rate) {}
  bool read(std::span<float> out) override {
    capture_.read(out);
    return true;
  }

 private:
  AlsaCapture capture_;
};

// s16le mono from a FIFO or file; blocks as the writer paces it.
class PipeInput final : public AudioInput {
 public:
  PipeInput(const std::string& path, const std::atomic<bool>* stop) : path_(path), stop_(stop) {
    // Non-blocking: opening a FIFO waits for no writer, and a stop is noticed.
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd_ < 0) throw DeviceError("capture pipe " + quote(path) + ": " + std::strerror(errno));
  }
  ~PipeInput() override { ::close(fd_); }
  bool read(std::span<float> out) override {
    raw_.resize(out.size() * 2);
    std::size_t got = 0;
    while (got < raw_.size()) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 50) == 0) {
        if (stop_ != nullptr && stop_->load()) return false;
        continue;
      }
      const ssize_t n = ::read(fd_, raw_.data() + got, raw_.size() - got);
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n < 0) return false;
      if (n == 0) {
        // End of file: the writer closed it, or none has come yet.
        if (heard_) return false;
        if (stop_ != nullptr && stop_->load()) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        continue;
      }
      heard_ = true;
      got += static_cast<std::size_t>(n);
    }
    for (std::size_t i = 0; i < out.size(); ++i) {
      const auto v = static_cast<std::int16_t>(static_cast<std::uint16_t>(raw_[2 * i]) |
                                               (static_cast<std::uint16_t>(raw_[2 * i + 1]) << 8));
      out[i] = static_cast<float>(v) / 32768.0f;
    }
    return true;
  }

 private:
  std::string path_;
  const std::atomic<bool>* stop_;
  int fd_ = -1;
  bool heard_ = false;  // a writer has written
  std::vector<std::uint8_t> raw_;
};

}  // namespace

std::unique_ptr<AudioInput> open_audio_input(const std::string& spec, int sample_rate,
                                             const std::atomic<bool>* stop) {
  const std::string prefix = kPipeCapturePrefix;
  if (spec.rfind(prefix, 0) == 0)
    return std::make_unique<PipeInput>(spec.substr(prefix.size()), stop);
  return std::make_unique<AlsaInput>(spec, sample_rate);
}

}  // namespace animrt::head
