#pragma once
// Art-Net (DMX512 over UDP, as lighting desks send it): one DMX channel of
// one universe selects a cue by its value. ArtDmx packets are read on the
// receiver's thread; a packet whose length disagrees with its header is
// counted and dropped. Packets of other kinds (polls, other universes) are
// counted and ignored.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "animrt/runtime/dmx_channel_watch.hpp"
#include "animrt/runtime/udp_receiver.hpp"

namespace animrt {

inline constexpr int kArtNetPort = 6454;

struct ArtDmx {
  int universe = 0;                    // the 15-bit port address: net, sub-net and universe
  std::span<const std::uint8_t> data;  // channel 1 is data[0]
};

enum class ArtNetParse { dmx, other, malformed };

// An ArtDmx packet: the "Art-Net" id, opcode 0x5000 (little-endian), the
// protocol version, sequence, physical port, the port address (SubUni, Net),
// the data length (big-endian, even, 2 to 512) and the data.
ArtNetParse parse_artnet(std::span<const std::uint8_t> packet, ArtDmx& out);

class ArtNetReceiver {
 public:
  using Handler = DmxChannelWatch::Handler;
  using FrameHandler = DmxChannelWatch::FrameHandler;

  // Listens at `host`:`port` for `universe`, channel `channel` (1-512; 0:
  // no cue channel, frames only).
  ArtNetReceiver(const std::string& host, int port, int universe, int channel, Handler handler,
                 FrameHandler frames = {});

  int port() const { return udp_.port(); }
  std::uint64_t packets() const { return udp_.datagrams(); }
  std::uint64_t frames() const { return watch_.frames(); }  // ArtDmx of our universe
  std::uint64_t malformed() const { return malformed_.load(); }
  std::uint64_t ignored() const { return ignored_.load(); }

 private:
  void take(std::span<const std::uint8_t> datagram);

  int universe_;
  DmxChannelWatch watch_;
  std::atomic<std::uint64_t> malformed_{0}, ignored_{0};
  UdpReceiver udp_;  // last: its thread stops before the rest goes
};

}  // namespace animrt
