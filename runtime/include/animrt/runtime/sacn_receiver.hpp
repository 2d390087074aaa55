#pragma once
// sACN (ANSI E1.31, streaming DMX512 over UDP, as lighting desks send it):
// one universe's DMX data selects cues by a channel's value, as Art-Net
// does. The receiver listens for unicast at its address and, when asked, for
// the universe's multicast group 239.255.hi.lo on the interface that has
// that address. Per the standard, a source's packets that arrive out of
// sequence are dropped, a higher-priority source silences lower ones, a
// source is forgotten after 2.5 s of silence or when it says its stream has
// ended, and preview data and other START codes are not output.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>

#include "animrt/runtime/dmx_channel_watch.hpp"
#include "animrt/runtime/udp_receiver.hpp"

namespace animrt {

inline constexpr int kSacnPort = 5568;
inline constexpr int kSacnMaxUniverse = 63999;
// E131_NETWORK_DATA_LOSS_TIMEOUT
inline constexpr double kSacnSourceLossS = 2.5;

struct SacnDmx {
  std::array<std::uint8_t, 16> cid{};  // the source's component id
  int priority = 100;                  // 0-200, higher wins
  int sequence = 0;
  bool preview = false;     // for visualisers only, never output
  bool terminated = false;  // the source's stream ends
  int universe = 1;
  int start_code = 0;                  // 0: DMX levels
  std::span<const std::uint8_t> data;  // channel 1 is data[0]
};

enum class SacnParse { dmx, other, malformed };

// A data packet: root layer (preamble 0x0010, post-amble 0, the ACN packet
// identifier, flags and length, vector 4, CID), framing layer (flags and
// length, vector 2, source name, priority, sync address, sequence, options,
// universe) and DMP layer (flags and length, vector 2, address and data type
// 0xa1, first address 0, increment 1, the property count, START code and
// slots). Every length must agree with the datagram's. Other root vectors
// (synchronisation, universe discovery) are `other`.
SacnParse parse_sacn(std::span<const std::uint8_t> packet, SacnDmx& out);

// The standard's source arbitration for one universe: which packets are
// output. Time is seconds on any steady clock.
class SacnSources {
 public:
  enum class Verdict { output, out_of_sequence, lower_priority, not_output };
  Verdict take(const SacnDmx& packet, double now_s);

 private:
  struct Source {
    std::array<std::uint8_t, 16> cid{};
    int sequence = 0;
    int priority = 0;
    double seen_s = -1e9;
    bool used = false;
  };
  static constexpr std::size_t kMaxSources = 8;
  Source* find(const std::array<std::uint8_t, 16>& cid, double now_s);
  std::array<Source, kMaxSources> sources_{};
};

class SacnReceiver {
 public:
  using Handler = DmxChannelWatch::Handler;
  using FrameHandler = DmxChannelWatch::FrameHandler;

  // Listens at `host`:`port` for `universe` (1-63999); with `multicast`,
  // also joins 239.255.hi.lo on the interface that has address `host`.
  // `channel` 0: no cue channel (frames only).
  SacnReceiver(const std::string& host, int port, bool multicast, int universe, int channel,
               Handler handler, FrameHandler frames = {});

  int port() const { return unicast_->port(); }
  std::uint64_t packets() const {
    return unicast_->datagrams() + (multicast_ ? multicast_->datagrams() : 0);
  }
  std::uint64_t frames() const { return watch_.frames(); }  // output for our universe
  std::uint64_t malformed() const { return malformed_.load(); }
  std::uint64_t out_of_sequence() const { return out_of_sequence_.load(); }
  std::uint64_t ignored() const { return ignored_.load(); }  // other kinds, universes, priorities

  static std::string group(int universe);  // 239.255.hi.lo

 private:
  void take(std::span<const std::uint8_t> datagram);

  int universe_;
  DmxChannelWatch watch_;
  // Both sockets' threads take packets (never the cycle's: a lock is fine).
  std::mutex arbitration_;
  SacnSources sources_;
  std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
  std::atomic<std::uint64_t> malformed_{0}, out_of_sequence_{0}, ignored_{0};
  std::unique_ptr<UdpReceiver> unicast_;  // last: their threads stop before the rest goes
  std::unique_ptr<UdpReceiver> multicast_;
};

}  // namespace animrt
