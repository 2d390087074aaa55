#include <errno.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>

#include "animrt/bridge/can/socketcan.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

std::string errno_text(int err) { return std::strerror(err); }

class SocketCanTransport final : public CanFrameTransport {
 public:
  SocketCanTransport(int fd, std::string interface) : fd_(fd), interface_(std::move(interface)) {}
  ~SocketCanTransport() override { ::close(fd_); }
  SocketCanTransport(const SocketCanTransport&) = delete;
  SocketCanTransport& operator=(const SocketCanTransport&) = delete;

  const std::string& interface() const override { return interface_; }

  void set_filters(std::span<const can_filter> filters) override {
    // An empty list would receive nothing; keep SocketCAN's meaning explicit.
    const socklen_t size = static_cast<socklen_t>(filters.size() * sizeof(can_filter));
    if (setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(), size) != 0) {
      throw DeviceError("CAN interface " + interface_ +
                        ": cannot set receive filters: " + errno_text(errno));
    }
  }

  bool send(const can_frame& frame) override {
    const ssize_t n = ::write(fd_, &frame, sizeof frame);
    if (n == static_cast<ssize_t>(sizeof frame)) return true;
    ++errors_.tx_dropped;  // ENOBUFS (queue full), ENETDOWN (bus-off, link down), ...
    return false;
  }

  bool receive(can_frame& frame, std::chrono::microseconds timeout) override {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const ssize_t n = ::read(fd_, &frame, sizeof frame);
      if (n == static_cast<ssize_t>(sizeof frame)) {
        if ((frame.can_id & CAN_ERR_FLAG) == 0) return true;
        const int change = count_error_frame(frame, errors_);
        if (change > 0) bus_off_ = true;
        if (change < 0) bus_off_ = false;
        // A flood of error frames must not hold the caller past its timeout.
        if (std::chrono::steady_clock::now() >= deadline) return false;
        continue;
      }
      if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        ++errors_.rx_overflows;  // e.g. ENOBUFS; the socket keeps working
      }
      const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return false;
      pollfd p{fd_, POLLIN, 0};
      timespec ts{static_cast<time_t>(left.count() / 1'000'000),
                  static_cast<long>((left.count() % 1'000'000) * 1000)};
      if (ppoll(&p, 1, &ts, nullptr) == 0) return false;
    }
  }

  const CanErrorCounters& errors() const override { return errors_; }
  bool bus_off() const override { return bus_off_; }
  Nanos now() const override { return MonotonicClock().now(); }

 private:
  int fd_;
  std::string interface_;
  CanErrorCounters errors_;
  bool bus_off_ = false;
};

int open_raw_socket(std::string& reason) {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd >= 0) return fd;
  const int err = errno;
  if (err == EAFNOSUPPORT || err == EPROTONOSUPPORT) {
    reason =
        "this kernel has no CAN support (socket(AF_CAN, SOCK_RAW, CAN_RAW): " + errno_text(err) +
        "); load the can and can-raw modules (modprobe can-raw)";
  } else {
    reason = "cannot create a CAN socket: " + errno_text(err);
  }
  return -1;
}

}  // namespace

std::string socketcan_unavailable_reason() {
  std::string reason;
  const int fd = open_raw_socket(reason);
  if (fd >= 0) ::close(fd);
  return reason;
}

std::unique_ptr<CanFrameTransport> open_socketcan(const std::string& interface) {
  const std::string who = "CAN interface " + interface + ": ";
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    throw DeviceError(who + "expected an interface name such as can0 (at most " +
                      std::to_string(IFNAMSIZ - 1) + " characters)");
  }
  std::string reason;
  const int fd = open_raw_socket(reason);
  if (fd < 0) throw DeviceError(who + reason);
  auto fail = [&](const std::string& why) {
    ::close(fd);
    throw DeviceError(who + why);
  };

  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface.c_str(), IFNAMSIZ - 1);
  if (ioctl(fd, SIOCGIFINDEX, &ifr) != 0) {
    fail("no such interface (" + errno_text(errno) + "); for a virtual one: ip link add dev " +
         interface + " type vcan");
  }
  const int index = ifr.ifr_ifindex;
  if (ioctl(fd, SIOCGIFFLAGS, &ifr) == 0 && (ifr.ifr_flags & IFF_UP) == 0) {
    fail("interface is down; bring it up: ip link set " + interface +
         " up type can bitrate 1000000 (or, for vcan: ip link set " + interface + " up)");
  }
  // Every controller error we can learn about, so they are counted.
  const can_err_mask_t mask = CAN_ERR_MASK;
  if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof mask) != 0) {
    fail("cannot enable error frames: " + errno_text(errno));
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = index;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    fail("cannot bind: " + errno_text(errno));
  }
  return std::make_unique<SocketCanTransport>(fd, interface);
}

}  // namespace animrt
