#include "animrt/sim/serial_line.hpp"

#include <poll.h>
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
           std::span<std::uint8_t> buffer, const LineHandlers& handlers) {
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
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    }
    // Hangup or error: not expected while the slave side is held open; do not spin.
    ::poll(&fds[1], 1, 10);
  }
}

}  // namespace animrt::sim::line
