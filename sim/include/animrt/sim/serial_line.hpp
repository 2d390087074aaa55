#pragma once
// The device side of a simulated serial servo line, shared by every
// simulated serial-servo family (Dynamixel, Feetech): the thread's loop
// that reads what the host sends and drops a packet left half received
// (a servo's receive timeout), the decoding of the bytes into packets with
// the family's codec (the same one the host's bus uses, servo_link.hpp),
// the wire time of bytes at the line's baud, and a write that gives up on
// a host that stopped reading.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include "animrt/bridge/lockstep_line.hpp"
#include "animrt/bridge/serial_servo/servo_link.hpp"
#include "animrt/core/clock.hpp"

namespace animrt::sim::line {

inline constexpr int kBitsPerByte = 10;     // start + 8 data + stop
inline constexpr int kWriteStallMs = 200;   // a host that stops reading loses answers after this
inline constexpr int kPacketSilenceMs = 5;  // a servo's receive timeout

void sleep_until_monotonic(Nanos t);
// A pseudo-terminal has no wire: the baud rate the host chose is the one it
// set on the line (termios), read here from either side. 0 when it is not a
// standard rate or cannot be read.
int line_baud(int fd);
// Sets the line's baud rate (a host that never sets one talks at it);
// false for a rate termios has no code for.
bool set_line_baud(int fd, int baud);
// Time `bytes` take on a line at `baud`.
Nanos wire_ns(std::size_t bytes, int baud);
// Writes `bytes` to the non-blocking `fd`, waiting at most kWriteStallMs at
// a time while the host does not read, and never once `wake_fd` is
// readable (the thread is stopping). Returns the bytes written.
std::size_t write_all(int fd, int wake_fd, std::span<const std::uint8_t> bytes);

// The thread's loop, until `stop` or `wake_fd` is readable: each read's
// bytes go to on_bytes(bytes, arrival); while partial() says a packet is
// half received, kPacketSilenceMs of silence calls on_silence(). On a
// lockstep line (if given), each read's bytes are taken once on_bytes has
// answered them.
struct LineHandlers {
  std::function<void(std::span<const std::uint8_t>, Nanos)> on_bytes;
  std::function<bool()> partial;
  std::function<void()> on_silence;
};
void serve(int master_fd, int wake_fd, const std::atomic<bool>& stop,
           std::span<std::uint8_t> buffer, const LineHandlers& handlers,
           LockstepLine* lockstep = nullptr);

// Counts of what the firmware could not take as a packet (read by other
// threads for statistics).
struct DecodeCounts {
  std::atomic<std::uint64_t> bad_checks{0};  // a servo ignores a packet it cannot trust
  std::atomic<std::uint64_t> malformed{0};
};

// Feeds `bytes` to the decoder and calls on_packet for every whole packet.
template <class Codec, class OnPacket>
void feed(const Codec& codec, typename Codec::Decoder& decoder, std::span<const std::uint8_t> bytes,
          DecodeCounts& counts, OnPacket&& on_packet) {
  std::size_t fed = 0;
  while (fed < bytes.size()) {
    fed += decoder.feed(bytes.subspan(fed));
    typename Codec::Packet packet;
    for (;;) {
      const servo::Frame r = codec.next(decoder, packet);
      if (r == servo::Frame::need_more) break;
      if (r == servo::Frame::bad_check) {
        ++counts.bad_checks;
      } else if (r == servo::Frame::malformed) {
        ++counts.malformed;
      } else {
        on_packet(packet);
      }
    }
  }
}

}  // namespace animrt::sim::line
