#include "output_file.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>

#include "animrt/core/input_file.hpp"
#include "subcommand.hpp"

namespace animrt::cli {

OutputFile::~OutputFile() {
  if (fd < 0) return;
  // Removed only while the path still names the empty file this made: not
  // one another run has written or put there since.
  struct stat open_st {
  }, path_st{};
  const bool ours = !created_.empty() && ::fstat(fd, &open_st) == 0 && open_st.st_size == 0 &&
                    ::lstat(created_.c_str(), &path_st) == 0 && path_st.st_dev == open_st.st_dev &&
                    path_st.st_ino == open_st.st_ino;
  if (ours) ::unlink(created_.c_str());
  ::close(fd);
}

bool OutputFile::open(const std::string& path) {
  // Not emptied yet: a command that fails before its end (bad input, a
  // stop) leaves the last run's file as it was, and no empty one where
  // there was none.
  fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd >= 0) {
    created_ = path;
    return true;
  }
  if (errno == EEXIST) fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
  if (fd < 0) error = errno;
  return fd >= 0;
}

bool OutputFile::write(const std::string& text) {
  created_.clear();
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && ::ftruncate(fd, 0) != 0) {
    error = errno;
    return false;
  }
  error = write_all(fd, text.data(), text.size());
  if (error != 0) return false;
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) error = errno;
  return closed == 0;
}

std::runtime_error cannot_write(const std::string& option, const std::string& path, int error) {
  const std::string why = error != 0 ? std::string(": ") + std::strerror(error) : "";
  return std::runtime_error(option + ": cannot write " + path + why);
}

bool open_summary_json(OutputFile& file, const std::string& path) {
  if (path.empty() || file.open(path)) return true;
  spdlog::error("{}", cannot_write("--summary-json", path, file.error).what());
  return false;
}

int write_summary_json(OutputFile& file, const std::string& path, const std::string& json,
                       int code) {
  if (!file.is_open() || file.write(json)) return code;
  std::cout << "RECORD LOST summary JSON: could not be written to " << path << ": "
            << std::strerror(file.error) << '\n';
  return code == kExitOk ? kExitRecordLost : code;
}

}  // namespace animrt::cli
