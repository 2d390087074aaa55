// Live sound sources: an ALSA capture device, or a pipe standing in for one.

#include "animrt/controllers/head/audio_input.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
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
  explicit PipeInput(const std::string& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw DeviceError("capture pipe " + quote(path) + ": " + std::strerror(errno));
  }
  ~PipeInput() override { ::close(fd_); }
  bool read(std::span<float> out) override {
    raw_.resize(out.size() * 2);
    std::size_t got = 0;
    while (got < raw_.size()) {
      const ssize_t n = ::read(fd_, raw_.data() + got, raw_.size() - got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;  // the writer closed it (or an error): the source ended
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
  int fd_ = -1;
  std::vector<std::uint8_t> raw_;
};

}  // namespace

std::unique_ptr<AudioInput> open_audio_input(const std::string& spec, int sample_rate) {
  const std::string prefix = kPipeCapturePrefix;
  if (spec.rfind(prefix, 0) == 0) return std::make_unique<PipeInput>(spec.substr(prefix.size()));
  return std::make_unique<AlsaInput>(spec, sample_rate);
}

}  // namespace animrt::head
