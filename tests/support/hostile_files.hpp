#pragma once
// Hostile inputs for the readers' tests: a FIFO that nobody writes to, and a
// small gzip file that inflates to far more than any input limit.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace animrt::test {

// A FIFO at `path` for as long as the object lives. A reader that should
// refuse it but opens it instead would block for ever; a helper thread then
// opens the writing end and closes it again, so such a reader sees the end
// of the file and the test fails instead of hanging. The non-blocking open
// succeeds only while some reader has the FIFO open, so a reader that
// refuses it is never disturbed.
class UnblockedFifo {
 public:
  explicit UnblockedFifo(std::string path) : path_(std::move(path)) {
    ::unlink(path_.c_str());
    if (::mkfifo(path_.c_str(), 0600) != 0) throw std::runtime_error("mkfifo " + path_);
    thread_ = std::thread([this] {
      while (!stop_) {
        const int fd = ::open(path_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
        if (fd >= 0) {
          ::close(fd);
          ++unblocked_;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
  }
  UnblockedFifo(const UnblockedFifo&) = delete;
  UnblockedFifo& operator=(const UnblockedFifo&) = delete;
  ~UnblockedFifo() {
    stop_ = true;
    thread_.join();
    ::unlink(path_.c_str());
  }
  const std::string& path() const { return path_; }
  // How often a reader had the FIFO open (0 when every reader refused it).
  int times_opened() const { return unblocked_; }

 private:
  std::string path_;
  std::atomic<bool> stop_{false};
  std::atomic<int> unblocked_{0};
  std::thread thread_;
};

// Writes `prefix` followed by `zeros` zero bytes as one gzip stream, made
// chunk by chunk (nothing of the inflated size is held in memory). Zeros
// deflate about 1000 to 1: 80 MiB become some 80 KB.
inline void write_gzip_bomb(const std::string& path, std::uint64_t zeros,
                            const std::string& prefix = "") {
  gzFile out = gzopen(path.c_str(), "wb9");
  if (out == nullptr) throw std::runtime_error("gzopen " + path);
  if (!prefix.empty()) gzwrite(out, prefix.data(), static_cast<unsigned>(prefix.size()));
  const std::vector<char> chunk(1 << 20, 0);
  while (zeros > 0) {
    const auto n = static_cast<unsigned>(std::min<std::uint64_t>(zeros, chunk.size()));
    if (gzwrite(out, chunk.data(), n) != static_cast<int>(n)) {
      gzclose(out);
      throw std::runtime_error("gzwrite " + path);
    }
    zeros -= n;
  }
  if (gzclose(out) != Z_OK) throw std::runtime_error("gzclose " + path);
}

}  // namespace animrt::test
