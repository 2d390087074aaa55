#include "fd_transport.hpp"

#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>

#include "animrt/bridge/lockstep_line.hpp"
#include "animrt/core/error.hpp"

namespace animrt::detail {
namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

timespec to_timespec(std::int64_t ns) {
  if (ns < 0) ns = 0;
  return timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

// Waits for `events` until the monotonic deadline, or until `wake_fd` (if
// >= 0) is readable; returns fd's revents, or 0 on timeout or wake-up.
// ppoll rather than poll: the bus timeouts are in microseconds.
short wait_for(int fd, short events, std::int64_t deadline_ns, int wake_fd = -1) {
  for (;;) {
    pollfd p[2] = {{fd, events, 0}, {wake_fd, POLLIN, 0}};  // a negative fd is skipped
    const timespec left = to_timespec(deadline_ns - now_ns());
    const int r = ppoll(p, 2, &left, nullptr);
    if (r > 0) return p[0].revents;
    if (r == 0) return 0;
    if (errno != EINTR) return POLLERR;
  }
}

}  // namespace

void FdTransport::line_gone(const char* how, int error) {
  if (failure_ != nullptr) return;
  failure_ = how;
  failure_errno_ = error;
}

bool FdTransport::write(std::span<const std::uint8_t> bytes) {
  if (failure_ != nullptr) {
    ++write_failures_;
    return false;
  }
  std::size_t done = 0;
  const bool ok = write_all(bytes, done);
  if (line_ != nullptr) line_->host_wrote(done);
  if (!ok) ++write_failures_;
  return ok;
}

bool FdTransport::write_all(std::span<const std::uint8_t> bytes, std::size_t& done) {
  const std::int64_t deadline = now_ns() + std::chrono::nanoseconds(timeout_).count();
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      // The other end is not reading: wait no longer than one bus timeout,
      // then give up on this packet (the device drops the partial packet
      // after its inter-byte silence).
      const short ev = wait_for(fd_, POLLOUT, deadline);
      if (ev == 0) return false;
      if ((ev & POLLOUT) == 0) {
        line_gone("line is gone (hangup or error)", 0);
        return false;
      }
      continue;
    }
    line_gone("write failed, line is gone", n < 0 ? errno : 0);
    return false;
  }
  return true;
}

std::size_t FdTransport::read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout) {
  if (buffer.empty() || failure_ != nullptr) return 0;
  // Following a lockstep line, the line says when nothing more will come;
  // the wall clock only guards against a hung device side.
  if (line_ != nullptr)
    timeout = std::max<std::chrono::microseconds>(timeout, LockstepLine::kGuard);
  const std::int64_t deadline = now_ns() + std::chrono::nanoseconds(timeout).count();
  bool waited = false;
  for (;;) {
    // Read first: when bytes are already queued this saves the poll.
    const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
    if (n > 0) return took(n);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
      line_gone("read failed, line is gone", errno);
      return 0;
    }
    // Nothing queued (EAGAIN, or 0 when the tty has VMIN = 0); a hangup also
    // reads 0, so poll tells the two apart. A settled lockstep line has
    // nothing more to send: the answer is missing now, not at the deadline.
    // (The wake-up is cleared before the look, so none is lost.)
    if (line_ != nullptr) {
      line_->clear_wake();
      if (line_->settled()) return 0;
    }
    if (waited && now_ns() >= deadline) return 0;
    const short ev = wait_for(fd_, POLLIN, deadline, line_ != nullptr ? line_->wake_fd() : -1);
    waited = true;
    if ((ev & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      // Bytes that came before the hangup are still handed out.
      const ssize_t last = ::read(fd_, buffer.data(), buffer.size());
      if (last > 0) return took(last);
      line_gone("line is gone (hangup)", last < 0 ? errno : 0);
      return 0;
    }
    if (ev == 0 && line_ == nullptr) return 0;
  }
}

std::size_t FdTransport::took(long n) {
  if (line_ != nullptr) line_->host_read(static_cast<std::size_t>(n));
  return static_cast<std::size_t>(n);
}

void FdTransport::discard_input() {
  if (failure_ != nullptr) return;
  if (line_ != nullptr) {
    discard_lockstep(now_ns() + std::chrono::nanoseconds(timeout_).count());
    return;
  }
  tcflush(fd_, TCIFLUSH);
  // tcflush leaves bytes that were still in flight in the driver (a pty's
  // flip buffer); read them away too, but never for longer than the timeout
  // or more than kMaxDiscard bytes: a device that keeps sending must not
  // keep us here.
  const std::int64_t deadline = now_ns() + std::chrono::nanoseconds(timeout_).count();
  std::uint8_t sink[256];
  std::size_t dropped = 0;
  while (dropped < kMaxDiscard && now_ns() < deadline) {
    const ssize_t n = ::read(fd_, sink, sizeof sink);
    if (n > 0) {
      dropped += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK)
      line_gone("read failed, line is gone", errno);
    return;
  }
}

// A lockstep line counts what the device side wrote: read exactly that away
// (tcflush would drop an unknown count, and the line would never settle).
void FdTransport::discard_lockstep(std::int64_t deadline_ns) {
  std::uint8_t sink[256];
  while (line_->unread() > 0) {
    const ssize_t n = ::read(fd_, sink, sizeof sink);
    if (n > 0) {
      took(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
      line_gone("read failed, line is gone", errno);
      return;
    }
    if (now_ns() >= deadline_ns) return;
    if ((wait_for(fd_, POLLIN, deadline_ns) & (POLLHUP | POLLERR | POLLNVAL)) != 0) return;
  }
}

}  // namespace animrt::detail

namespace animrt {

std::string describe_failure(const ByteTransport& transport) {
  std::string message = "serial port " + transport.port() + ": ";
  message += transport.failure() != nullptr ? transport.failure() : "working";
  if (transport.failure_errno() != 0)
    message += std::string(": ") + std::strerror(transport.failure_errno());
  return message;
}

}  // namespace animrt

namespace animrt::detail {

void throw_open_error(const std::string& port, const std::string& reason, int error) {
  std::string message = "cannot open serial port " + port + ": " + reason;
  if (error == EACCES || error == EPERM) {
    message +=
        " (is the user in the 'dialout' group? add it with 'sudo usermod -aG dialout "
        "$USER' and log in again)";
  } else if (error == EBUSY) {
    message +=
        " (another program may be using the port; also check the user is in the "
        "'dialout' group)";
  }
  throw DeviceError(message);
}

}  // namespace animrt::detail
