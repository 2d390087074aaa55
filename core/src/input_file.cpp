#include "animrt/core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace animrt {
namespace {

std::string size_text(std::uintmax_t bytes) {
  if (bytes >= (std::uintmax_t{1} << 20) && bytes % (std::uintmax_t{1} << 20) == 0)
    return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory";
  if (S_ISFIFO(mode)) return "is not a regular file (FIFO)";
  if (S_ISCHR(mode)) return "is not a regular file (character device)";
  if (S_ISBLK(mode)) return "is not a regular file (block device)";
  if (S_ISSOCK(mode)) return "is not a regular file (socket)";
  if (!S_ISREG(mode)) return "is not a regular file";
  return "";
}

std::string problem_of(const struct stat& st, std::uintmax_t max_bytes) {
  if (std::string kind = kind_of(st.st_mode); !kind.empty()) return kind;
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  if (size > max_bytes)
    return "is " + size_text(size) + ", more than the " + size_text(max_bytes) + " limit";
  return "";
}

std::string errno_problem(int error) {
  return std::string("cannot open file: ") + std::strerror(error);
}

// A missing file is named plainly (kFileMissing) where the path is quoted
// after a key; where the path leads the message, the errno text reads better.
constexpr const char* kMissing = kFileMissing;

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(Location{path, 0, 0}, "", problem);
}

}  // namespace

std::string input_file_problem(const std::string& path, std::uintmax_t max_bytes) {
  if (path.empty()) return "no file name given";
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return errno == ENOENT ? kMissing : errno_problem(errno);
  return problem_of(st, max_bytes);
}

void check_input_file(const std::string& path, std::uintmax_t max_bytes) {
  if (std::string problem = input_file_problem(path, max_bytes); !problem.empty())
    fail(path, problem == kMissing ? errno_problem(ENOENT) : problem);
}

std::string read_input_file(const std::string& path, std::uintmax_t max_bytes) {
  check_input_file(path, max_bytes);
  // O_NONBLOCK: should the path have become a FIFO since the check, open and
  // read return at once instead of waiting for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) fail(path, errno_problem(errno));
  struct stat st {};
  std::string problem = ::fstat(fd, &st) != 0 ? errno_problem(errno) : problem_of(st, max_bytes);
  std::string text;
  if (problem.empty()) {
    text.reserve(static_cast<std::size_t>(st.st_size));
    char chunk[65536];
    while (true) {
      const ssize_t n = ::read(fd, chunk, sizeof chunk);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        problem = std::string("cannot read: ") + std::strerror(errno);
        break;
      }
      if (n == 0) break;
      // A file that grows while it is read is still held to the limit.
      if (text.size() + static_cast<std::size_t>(n) > max_bytes) {
        problem = "grew past the " + size_text(max_bytes) + " limit while being read";
        break;
      }
      text.append(chunk, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  if (!problem.empty()) fail(path, problem);
  return text;
}

}  // namespace animrt
