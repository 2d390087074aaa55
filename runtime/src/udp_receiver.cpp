#include "animrt/runtime/udp_receiver.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace animrt {
namespace {

// How often the thread looks whether it should end.
constexpr int kPollMs = 100;
constexpr std::size_t kMaxDatagram = 65536;

int bind_udp(const std::string& what, const std::string& host, int port, bool reuse,
             int& bound_port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found);
  if (rc != 0) {
    throw std::runtime_error(what + ": cannot bind " + host + ":" + service + ": " +
                             ::gai_strerror(rc));
  }
  int fd = -1;
  int error = 0;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    const int on = 1;
    if (fd >= 0 && reuse) ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    if (fd >= 0 && ::bind(fd, a->ai_addr, a->ai_addrlen) != 0) {
      error = errno;
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(found);
  if (fd < 0) {
    throw std::runtime_error(what + ": cannot bind " + host + ":" + service + ": " +
                             std::strerror(error));
  }
  sockaddr_storage at{};
  socklen_t length = sizeof at;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&at), &length);
  bound_port = at.ss_family == AF_INET6
                   ? ntohs(reinterpret_cast<const sockaddr_in6*>(&at)->sin6_port)
                   : ntohs(reinterpret_cast<const sockaddr_in*>(&at)->sin_port);
  return fd;
}

void join_group(const std::string& what, int fd, const UdpOptions& options) {
  ip_mreq request{};
  std::string problem;
  if (::inet_pton(AF_INET, options.group.c_str(), &request.imr_multiaddr) != 1 ||
      ::inet_pton(AF_INET, options.interface.c_str(), &request.imr_interface) != 1) {
    problem = "multicast needs IPv4 addresses";
  } else if (::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &request, sizeof request) != 0) {
    problem = std::strerror(errno);
  }
  if (problem.empty()) return;
  ::close(fd);
  throw std::runtime_error(what + ": cannot join multicast group " + options.group +
                           " on the interface of " + options.interface + ": " + problem);
}

}  // namespace

UdpReceiver::UdpReceiver(const std::string& what, const std::string& host, int port,
                         Handler handler, const UdpOptions& options)
    : handler_(std::move(handler)) {
  fd_ = bind_udp(what, host, port, options.reuse_address, port_);
  if (!options.group.empty()) {
    join_group(what, fd_, options);
  } else {
    // A socket bound to a wildcard address takes no group another socket joined.
    const int off = 0;
    ::setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_ALL, &off, sizeof off);
  }
  // Room for a burst from a show controller while this thread is not running.
  // (SO_RCVBUFFORCE passes the system's cap where permitted; else the cap holds.)
  const int buffer = 1 << 20;
  if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &buffer, sizeof buffer) != 0) {
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
  }
  thread_ = std::thread([this] { receive(); });
}

UdpReceiver::~UdpReceiver() {
  running_.store(false);
  if (thread_.joinable()) thread_.join();
  ::close(fd_);
}

void UdpReceiver::receive() {
  std::vector<std::uint8_t> buffer(kMaxDatagram);
  while (running_.load()) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, kPollMs) <= 0) continue;
    sockaddr_storage peer{};
    socklen_t peer_size = sizeof peer;
    const ssize_t n = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_TRUNC,
                                 reinterpret_cast<sockaddr*>(&peer), &peer_size);
    if (n < 0) continue;
    datagrams_.fetch_add(1);
    UdpSender from;
    if (peer.ss_family == AF_INET) {
      const auto& in = reinterpret_cast<const sockaddr_in&>(peer);
      std::memcpy(from.address.data(), &in.sin_addr, 4);
      from.port = ntohs(in.sin_port);
    } else if (peer.ss_family == AF_INET6) {
      const auto& in6 = reinterpret_cast<const sockaddr_in6&>(peer);
      std::memcpy(from.address.data(), &in6.sin6_addr, 16);
      from.port = ntohs(in6.sin6_port);
    }
    const auto size = static_cast<std::size_t>(n);
    handler_(size > buffer.size() ? std::span<const std::uint8_t>()
                                  : std::span<const std::uint8_t>(buffer.data(), size),
             from);
  }
}

}  // namespace animrt
