#include "animrt/sim/maestro/pty_pair.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "animrt/core/error.hpp"

namespace animrt::sim {

PtyPair::PtyPair(const std::string& owner) {
  const auto fail = [&](const char* what, int error) {
    if (master_ >= 0) ::close(master_);
    if (slave_ >= 0) ::close(slave_);
    throw DeviceError(owner + ": " + what + ": " + std::strerror(error));
  };
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_ < 0) fail("posix_openpt", errno);
  if (::grantpt(master_) != 0) fail("grantpt", errno);
  if (::unlockpt(master_) != 0) fail("unlockpt", errno);
  char name[128];
  if (const int error = ::ptsname_r(master_, name, sizeof(name)); error != 0)
    fail("ptsname", error);
  path_ = name;
  slave_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave_ < 0) fail("open pty slave", errno);
  termios tio{};
  if (::tcgetattr(slave_, &tio) != 0) fail("tcgetattr", errno);
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  if (::tcsetattr(slave_, TCSANOW, &tio) != 0) fail("tcsetattr", errno);
  if (::fcntl(master_, F_SETFL, O_NONBLOCK) != 0) fail("fcntl", errno);
}

PtyPair::~PtyPair() {
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
}

WakePipe::WakePipe() {
  if (::pipe2(fds_, O_CLOEXEC | O_NONBLOCK) != 0) {
    throw DeviceError(std::string("pipe: ") + std::strerror(errno));
  }
}

WakePipe::~WakePipe() {
  for (int fd : fds_) {
    if (fd >= 0) ::close(fd);
  }
}

void WakePipe::wake() {
  const char b = 1;
  [[maybe_unused]] const ssize_t n = ::write(fds_[1], &b, 1);
}

void WakePipe::drain() {
  char buf[16];
  while (::read(fds_[0], buf, sizeof buf) > 0) {
  }
}

}  // namespace animrt::sim
