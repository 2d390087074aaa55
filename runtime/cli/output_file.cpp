#include "output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

#include "animrt/core/input_file.hpp"

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
  error = write_all(fd, text.data(), text.size());
  if (error != 0) return false;
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) error = errno;
  return closed == 0;
}

}  // namespace animrt::cli
