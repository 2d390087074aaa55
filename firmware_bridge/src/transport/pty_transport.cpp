// Pseudo-terminals through plain termios: libserialport cannot open them (it
// needs sysfs entries and modem-line ioctls that a pty lacks).

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

#include "fd_transport.hpp"

namespace animrt::detail {
namespace {

// Linux device majors (Documentation/admin-guide/devices.txt).
constexpr unsigned kUnix98PtySlaveFirst = 136;  // /dev/pts/N, 136..143
constexpr unsigned kUnix98PtySlaveLast = 143;
constexpr unsigned kLegacyPtySlave = 3;  // /dev/ttyp*

struct Speed {
  int baud;
  speed_t code;
};
constexpr Speed kSpeeds[] = {
    {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
    {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
    {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
    {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000},
    {3500000, B3500000}, {4000000, B4000000},
};

bool standard_speed(int baud, speed_t& out) {
  for (const Speed& s : kSpeeds) {
    if (s.baud == baud) {
      out = s.code;
      return true;
    }
  }
  return false;
}

class PtyTransport final : public FdTransport {
 public:
  PtyTransport(std::string port, int fd) : FdTransport(std::move(port), fd) {}
  ~PtyTransport() override { ::close(fd()); }
  PtyTransport(const PtyTransport&) = delete;
  PtyTransport& operator=(const PtyTransport&) = delete;
};

}  // namespace

bool is_pseudo_terminal(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISCHR(st.st_mode)) return false;
  const unsigned m = major(st.st_rdev);
  return (m >= kUnix98PtySlaveFirst && m <= kUnix98PtySlaveLast) || m == kLegacyPtySlave;
}

}  // namespace animrt::detail

namespace animrt {

bool carries_baud(const std::string& port, int baud) {
  char resolved[PATH_MAX];
  if (::realpath(port.c_str(), resolved) == nullptr || !detail::is_pseudo_terminal(resolved)) {
    return true;
  }
  speed_t speed{};
  return detail::standard_speed(baud, speed);
}

}  // namespace animrt

namespace animrt::detail {

std::unique_ptr<ByteTransport> open_pty(const std::string& port, const std::string& device,
                                        int baud) {
  const int fd = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    throw_open_error(port, std::strerror(error), error);
  }
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) {
    const int error = errno;
    ::close(fd);
    throw_open_error(port, std::string("tcgetattr: ") + std::strerror(error), error);
  }
  // Raw 8N1, no flow control. VMIN 1 with O_NONBLOCK: a read returns what is
  // queued, or EAGAIN when nothing is (we wait in poll, not in the driver).
  cfmakeraw(&tio);
  tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS);
  tio.c_cflag |= CS8 | CLOCAL | CREAD;
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 1;
  tio.c_cc[VTIME] = 0;
  // A pty ignores the speed; set it anyway so the line reads back as configured.
  speed_t speed{};
  if (standard_speed(baud, speed)) {
    cfsetispeed(&tio, speed);
    cfsetospeed(&tio, speed);
  }
  if (tcsetattr(fd, TCSANOW, &tio) != 0) {
    const int error = errno;
    ::close(fd);
    throw_open_error(port, std::string("tcsetattr: ") + std::strerror(error), error);
  }
  return std::make_unique<PtyTransport>(port, fd);
}

}  // namespace animrt::detail
