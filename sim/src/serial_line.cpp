#include "animrt/sim/serial_line.hpp"

#include <poll.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace animrt::sim::line {

void sleep_until_monotonic(Nanos t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(t % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

namespace {

struct Rate {
  int baud;
  speed_t code;
};
constexpr Rate kRates[] = {
    {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
    {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
    {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
    {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000},
    {3500000, B3500000}, {4000000, B4000000},
};

}  // namespace

int line_baud(int fd) {
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) return 0;
  const speed_t code = ::cfgetospeed(&tio);
  for (const Rate& r : kRates) {
    if (r.code == code) return r.baud;
  }
  return 0;
}

bool set_line_baud(int fd, int baud) {
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) return false;
  for (const Rate& r : kRates) {
    if (r.baud == baud) {
      ::cfsetispeed(&tio, r.code);
      ::cfsetospeed(&tio, r.code);
      return ::tcsetattr(fd, TCSANOW, &tio) == 0;
    }
  }
  return false;
}

Nanos wire_ns(std::size_t bytes, int baud) {
  return static_cast<Nanos>(bytes) * kBitsPerByte * 1'000'000'000 / std::max(baud, 1);
}

std::size_t write_all(int fd, int wake_fd, std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) {
      // The host is not reading: wait a little, as a line would not.
      pollfd fds[2] = {{fd, POLLOUT, 0}, {wake_fd, POLLIN, 0}};
      if (::poll(fds, 2, kWriteStallMs) > 0 && fds[1].revents == 0 && (fds[0].revents & POLLOUT)) {
        continue;
      }
    }
    break;
  }
  return done;
}

void serve(int master_fd, int wake_fd, const std::atomic<bool>& stop,
           std::span<std::uint8_t> buffer, const LineHandlers& handlers, LockstepLine* lockstep) {
  const MonotonicClock wall;
  Nanos last_byte = 0;
  while (!stop.load()) {
    pollfd fds[2] = {{master_fd, POLLIN, 0}, {wake_fd, POLLIN, 0}};
    // With a packet half received, wait only for the inter-byte silence.
    const bool partial = handlers.partial();
    const int ready = ::poll(fds, 2, partial ? kPacketSilenceMs : -1);
    if (ready < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (partial && (ready == 0 || wall.now() - last_byte > Nanos{kPacketSilenceMs} * 1'000'000)) {
      handlers.on_silence();
    }
    if (ready == 0) continue;
    if (fds[1].revents != 0) break;
    if (fds[0].revents & POLLIN) {
      const ssize_t n = ::read(master_fd, buffer.data(), buffer.size());
      if (n > 0) {
        last_byte = wall.now();
        handlers.on_bytes(buffer.first(static_cast<std::size_t>(n)), last_byte);
        if (lockstep != nullptr) lockstep->device_took(static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    }
    // Hangup or error: not expected while the slave side is held open; do not spin.
    ::poll(&fds[1], 1, 10);
  }
}

}  // namespace animrt::sim::line
