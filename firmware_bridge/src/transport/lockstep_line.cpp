#include "animrt/bridge/lockstep_line.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "animrt/core/error.hpp"

namespace animrt {

LockstepLine::LockstepLine() : wake_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
  if (wake_fd_ < 0)
    throw DeviceError(std::string("lockstep line: eventfd: ") + std::strerror(errno));
}

LockstepLine::~LockstepLine() { ::close(wake_fd_); }

bool LockstepLine::settled() const {
  // Took first: what the device wrote before it took the host's last bytes
  // is then counted in device_wrote_.
  const bool serving = serving_.load(std::memory_order_acquire);
  const std::uint64_t took = device_took_.load(std::memory_order_acquire);
  if (serving && took != host_wrote_.load(std::memory_order_acquire)) return false;
  return host_read_ >= device_wrote_.load(std::memory_order_acquire);
}

bool LockstepLine::device_caught_up() const {
  return !serving_.load(std::memory_order_acquire) ||
         device_took_.load(std::memory_order_acquire) ==
             host_wrote_.load(std::memory_order_acquire);
}

std::uint64_t LockstepLine::unread() const {
  const std::uint64_t wrote = device_wrote_.load(std::memory_order_acquire);
  return wrote > host_read_ ? wrote - host_read_ : 0;
}

void LockstepLine::clear_wake() const {
  std::uint64_t count = 0;
  [[maybe_unused]] const ssize_t n = ::read(wake_fd_, &count, sizeof count);
}

void LockstepLine::device_took(std::size_t bytes) {
  device_took_.fetch_add(bytes, std::memory_order_release);
  wake();
}

void LockstepLine::device_serving(bool serving) {
  serving_.store(serving, std::memory_order_release);
  wake();
}

void LockstepLine::wake() {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
}

}  // namespace animrt
