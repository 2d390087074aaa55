#include "output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

namespace animrt::cli {

OutputFile::~OutputFile() {
  if (fd >= 0) ::close(fd);
}

bool OutputFile::open(const std::string& path) {
  fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) error = errno;
  return fd >= 0;
}

bool OutputFile::write(const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      error = n < 0 ? errno : EIO;
      return false;
    }
  }
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) error = errno;
  return closed == 0;
}

}  // namespace animrt::cli
