#pragma once
// Art-Net (DMX512 over UDP, as lighting desks send it): one DMX channel of
// one universe selects a cue by its value. ArtDmx packets are read on the
// receiver's thread; a packet whose length disagrees with its header, or of
// a protocol version before 14, is counted and dropped. Packets of other
// kinds (polls, other universes) are counted and ignored. As an Art-Net
// node does, two sources (IP addresses) of the universe are merged, the
// highest level of each channel winning (HTP); a third is ignored until one
// of them has been silent for 10 s.

#include <array>
#include <atomic>
#include <chrono>
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
  int sequence = 0;                    // 1-255, wrapping past 0; 0: not used
  std::span<const std::uint8_t> data;  // channel 1 is data[0]
};

enum class ArtNetParse { dmx, other, malformed };

// An ArtDmx packet: the "Art-Net" id, opcode 0x5000 (little-endian), the
// protocol version (big-endian, 14 or later), sequence, physical port, the
// port address (SubUni, Net), the data length (big-endian, even, 2 to 512)
// and the data.
ArtNetParse parse_artnet(std::span<const std::uint8_t> packet, ArtDmx& out);

// The universe's sources, merged: up to two at once (a source silent for
// 10 s is forgotten), each channel at the higher of their levels.
class ArtNetSources {
 public:
  enum class Verdict { output, out_of_sequence, third_source };
  static constexpr double kForgetS = 10.0;
  // On output, merged() is the frame to play.
  Verdict take(const UdpSender& from, const ArtDmx& dmx, double now_s);
  std::span<const std::uint8_t> merged() const { return {merged_.data(), merged_length_}; }

 private:
  struct Source {
    std::array<std::uint8_t, 16> address{};
    std::array<std::uint8_t, 512> levels{};
    std::size_t length = 0;
    int sequence = 0;
    double seen_s = -1e9;
    bool used = false;
  };
  std::array<Source, 2> sources_{};
  std::array<std::uint8_t, 512> merged_{};
  std::size_t merged_length_ = 0;
};

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
  std::uint64_t out_of_sequence() const { return out_of_sequence_.load(); }
  std::uint64_t ignored() const { return ignored_.load(); }  // other kinds, universes, sources

 private:
  void take(std::span<const std::uint8_t> datagram, const UdpSender& from);

  int universe_;
  DmxChannelWatch watch_;
  ArtNetSources sources_;  // the receiver's thread alone uses it
  std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
  std::atomic<std::uint64_t> malformed_{0}, out_of_sequence_{0}, ignored_{0};
  UdpReceiver udp_;  // last: its thread stops before the rest goes
};

}  // namespace animrt
