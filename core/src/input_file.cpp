#include "animrt/core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

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

void check_replaceable_file(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return;  // nothing there (or the write will say why)
  if (S_ISLNK(st.st_mode)) return;              // the rename replaces the link, not its target
  if (std::string kind = kind_of(st.st_mode); !kind.empty()) fail(path, kind);
}

int write_all(int fd, const void* data, std::size_t size, std::size_t* written) {
  const auto* bytes = static_cast<const char*>(data);
  std::size_t done = 0;
  int error = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, bytes + done, size - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      error = n < 0 ? errno : EIO;
      break;
    }
  }
  if (written != nullptr) *written = done;
  return error;
}

namespace {

// What is wrong with the nearest existing one of `folder` and its parents
// as the place a folder is made in: "" when it is a folder (the missing rest
// can be made) or nothing exists.
std::string nearest_existing_parent_problem(std::filesystem::path folder) {
  namespace fs = std::filesystem;
  for (; !folder.empty(); folder = folder.parent_path()) {
    std::error_code ec;
    const fs::file_status st = fs::status(folder, ec);
    if (fs::exists(st)) {
      return fs::is_directory(st) ? "" : "\"" + folder.string() + "\" is a file, not a folder";
    }
    if (folder == folder.parent_path()) break;
  }
  return {};
}

}  // namespace

std::string output_file_problem(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return "an empty path, expected a file to write";
  std::error_code ec;
  // A link is written through: judged by what it points to, so a dangling
  // link into a missing folder is named here, not after the work.
  if (fs::is_symlink(fs::symlink_status(path, ec))) {
    const fs::file_status target = fs::status(path, ec);
    if (ec == std::errc::too_many_symbolic_link_levels)
      return "is a link that cannot be followed: " + ec.message();
    if (!fs::exists(target)) {
      fs::path to = fs::read_symlink(path, ec);
      if (ec) return "is a link that cannot be read: " + ec.message();
      if (to.is_relative()) to = fs::path(path).parent_path() / to;
      const std::string problem = output_file_problem(to.string());
      if (!problem.empty()) return "is a link to \"" + to.string() + "\": " + problem;
    }
  }
  if (fs::is_directory(path, ec)) return "is a folder, expected a file to write";
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  const fs::file_status st = fs::status(folder, ec);
  // A folder that cannot be looked at (no permission) is not a missing one.
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
    return "its folder \"" + folder.string() + "\": " + ec.message();
  if (!fs::exists(st)) return "its folder \"" + folder.string() + "\" does not exist";
  if (!fs::is_directory(st)) return "\"" + folder.string() + "\" is a file, not a folder";
  return {};
}

std::string output_folder_problem(const std::string& path) {
  if (path.empty()) return "an empty path, expected a folder";
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_directory(st))
    return "is a file, expected a folder";
  return nearest_existing_parent_problem(path);
}

void check_input_file(const std::string& path, std::uintmax_t max_bytes) {
  if (std::string problem = input_file_problem(path, max_bytes); !problem.empty())
    fail(path, problem == kMissing ? errno_problem(ENOENT) : problem);
}

namespace {

// Reads the whole of `path` into `out` (std::string or a byte vector) after
// the checks of check_input_file.
template <class Buffer>
void read_whole(const std::string& path, std::uintmax_t max_bytes, Buffer& out) {
  check_input_file(path, max_bytes);
  // O_NONBLOCK: should the path have become a FIFO since the check, open and
  // read return at once instead of waiting for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) fail(path, errno_problem(errno));
  struct stat st {};
  std::string problem = ::fstat(fd, &st) != 0 ? errno_problem(errno) : problem_of(st, max_bytes);
  if (problem.empty()) {
    out.reserve(static_cast<std::size_t>(st.st_size));
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
      if (out.size() + static_cast<std::size_t>(n) > max_bytes) {
        problem = "grew past the " + size_text(max_bytes) + " limit while being read";
        break;
      }
      out.insert(out.end(), chunk, chunk + n);
    }
  }
  ::close(fd);
  if (!problem.empty()) fail(path, problem);
}

bool is_gzip(const std::vector<std::uint8_t>& bytes) {
  return bytes.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b;
}

// Inflates gzip members one after the other (as gzip -d does) into a buffer
// whose capacity never exceeds the limit: growth doubles up to it, never
// past it, so refusing a bomb costs at most the limit.
std::vector<std::uint8_t> inflate_gzip(const std::string& path,
                                       const std::vector<std::uint8_t>& packed,
                                       std::uintmax_t max_inflated) {
  z_stream z{};
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) fail(path, "cannot start gzip inflation");
  std::vector<std::uint8_t> out;
  std::string problem;
  z.next_in = const_cast<Bytef*>(packed.data());
  std::size_t left = packed.size();
  std::uint8_t chunk[65536];
  for (;;) {
    const auto feed = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
    z.avail_in = feed;
    z.next_out = chunk;
    z.avail_out = sizeof chunk;
    const int rc = inflate(&z, Z_NO_FLUSH);
    left -= feed - z.avail_in;
    const std::size_t produced = sizeof chunk - z.avail_out;
    if (out.size() + produced > max_inflated) {
      problem = "gzip data inflates to more than the " + size_text(max_inflated) + " limit";
      break;
    }
    if (out.size() + produced > out.capacity()) {
      out.reserve(static_cast<std::size_t>(std::min<std::uintmax_t>(
          std::max<std::uintmax_t>(2 * out.capacity(), out.size() + produced), max_inflated)));
    }
    out.insert(out.end(), chunk, chunk + produced);
    if (rc == Z_STREAM_END) {
      // Another member may follow; trailing zero padding ends the stream too.
      if (left == 0 || std::all_of(z.next_in, z.next_in + left, [](Bytef b) { return b == 0; }))
        break;
      if (inflateReset(&z) != Z_OK) {
        problem = "broken gzip data";
        break;
      }
      continue;
    }
    if (rc == Z_BUF_ERROR && left == 0 && produced == 0) {
      problem = "gzip data is truncated";
      break;
    }
    if (rc != Z_OK && rc != Z_BUF_ERROR) {
      problem = std::string("broken gzip data (") + (z.msg != nullptr ? z.msg : "zlib error") + ")";
      break;
    }
  }
  inflateEnd(&z);
  if (!problem.empty()) fail(path, problem);
  return out;
}

}  // namespace

std::string read_input_file(const std::string& path, std::uintmax_t max_bytes) {
  std::string text;
  read_whole(path, max_bytes, text);
  return text;
}

std::vector<std::uint8_t> read_input_bytes(const std::string& path, std::uintmax_t max_bytes,
                                           std::uintmax_t max_inflated) {
  std::vector<std::uint8_t> bytes;
  read_whole(path, max_bytes, bytes);
  if (!is_gzip(bytes)) return bytes;
  return inflate_gzip(path, bytes, max_inflated);
}

void check_header_count(const std::string& path, const std::string& key, const std::string& what,
                        std::uint64_t count, std::uint64_t item_bytes, std::uint64_t available) {
  if (item_bytes == 0 || count <= available / item_bytes) return;
  throw InputError(Location{path, 0, 0}, key,
                   what + " (" + std::to_string(count) + " x " + std::to_string(item_bytes) +
                       " bytes) is larger than the file (" + std::to_string(available) + " bytes)");
}

}  // namespace animrt
