#pragma once
// Open Sound Control 1.0 over UDP: show controllers, lighting desks and
// sensors send cues this way. The receiver runs on its own thread (never in
// the cycle); each message it parses is handed to a handler, which reaches
// the cycle through lock-free controls. A malformed packet is counted and
// dropped; the receiver goes on.

#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "animrt/runtime/udp_receiver.hpp"

namespace animrt {

struct OscMessage {
  std::string address;  // "/cue/hello"
  // The numeric arguments in order: int32, float32, int64, float64, and the
  // booleans T and F as 1 and 0 (a controller's "false" resumes a pause).
  std::vector<double> numbers;
};

// Appends the messages of one packet (a message, or a bundle of them, nested
// up to a few levels) to `out`. False when the packet is malformed (then
// `out` may hold part of it and should be dropped). Address patterns are
// matched literally.
bool parse_osc_packet(std::span<const std::uint8_t> packet, std::vector<OscMessage>& out);

class OscReceiver {
 public:
  // Returns false for an address nobody answers (counted as unknown).
  using Handler = std::function<bool(const OscMessage&)>;

  // Binds UDP `host`:`port` (port 0: a free one). Throws std::runtime_error
  // naming the address when it cannot.
  OscReceiver(const std::string& host, int port, Handler handler);

  int port() const { return udp_.port(); }
  std::uint64_t packets() const { return udp_.datagrams(); }
  std::uint64_t malformed() const { return malformed_.load(); }
  std::uint64_t messages() const { return messages_.load(); }
  std::uint64_t unknown() const { return unknown_.load(); }

 private:
  void take(std::span<const std::uint8_t> datagram);

  Handler handler_;
  std::vector<OscMessage> messages_buffer_;  // the receiving thread's
  std::atomic<std::uint64_t> malformed_{0}, messages_{0}, unknown_{0};
  UdpReceiver udp_;  // last: its thread stops before the rest goes
};

}  // namespace animrt
