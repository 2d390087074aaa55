#pragma once
// A UDP port read on a thread of its own (never the cycle's): each datagram
// is handed to a handler on that thread. Show-control triggers (OSC,
// Art-Net) arrive this way.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <thread>

namespace animrt {

struct UdpOptions {
  bool reuse_address = false;  // share the port with another socket (unicast and multicast)
  std::string group;           // a multicast group to join, empty: none
  std::string interface;       // the address of the interface to join it on
};

// Where a datagram came from: the sender's IP address (IPv4 in the first
// four bytes) and port.
struct UdpSender {
  std::array<std::uint8_t, 16> address{};
  std::uint16_t port = 0;
  bool operator==(const UdpSender&) const = default;
};

class UdpReceiver {
 public:
  // A datagram longer than the largest UDP payload comes as an empty span.
  using Handler =
      std::function<void(std::span<const std::uint8_t> datagram, const UdpSender& from)>;

  // Binds UDP `host`:`port` (port 0: a free one). Throws std::runtime_error
  // naming `what` and the address when it cannot.
  UdpReceiver(const std::string& what, const std::string& host, int port, Handler handler,
              const UdpOptions& options = {});
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;

  int port() const { return port_; }
  std::uint64_t datagrams() const { return datagrams_.load(); }

 private:
  void receive();

  int fd_ = -1;
  int port_ = 0;
  Handler handler_;
  std::atomic<bool> running_{true};
  std::atomic<std::uint64_t> datagrams_{0};
  std::thread thread_;
};

}  // namespace animrt
