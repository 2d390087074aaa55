#include "animrt/runtime/artnet_receiver.hpp"

#include <cstring>

namespace animrt {
namespace {

constexpr std::size_t kHeader = 18;
constexpr std::uint16_t kOpDmx = 0x5000;

}  // namespace

ArtNetParse parse_artnet(std::span<const std::uint8_t> packet, ArtDmx& out) {
  static constexpr char kId[8] = {'A', 'r', 't', '-', 'N', 'e', 't', '\0'};
  if (packet.size() < 10 || std::memcmp(packet.data(), kId, sizeof kId) != 0) {
    return ArtNetParse::malformed;
  }
  const std::uint16_t opcode = static_cast<std::uint16_t>(packet[8] | (packet[9] << 8));
  if (opcode != kOpDmx) return ArtNetParse::other;
  if (packet.size() < kHeader) return ArtNetParse::malformed;
  const std::size_t length = (std::size_t{packet[16]} << 8) | packet[17];
  // Art-Net asks senders for an even length, but desks and scripts that
  // send an odd number of channels exist: taken, with or without the
  // padding byte that makes the data even.
  const std::size_t carried = packet.size() - kHeader;
  const bool padded = length % 2 == 1 && carried == length + 1;
  if (length < 1 || length > 512 || (carried != length && !padded)) {
    return ArtNetParse::malformed;
  }
  // The Port-Address is 15 bits: a Net with its top bit set is no address
  // (taken as 0x7f-masked, Net 0x80 played universe 0).
  if ((packet[15] & 0x80) != 0) {
    return ArtNetParse::malformed;
  }
  out.universe = ((packet[15] & 0x7f) << 8) | packet[14];
  out.data = packet.subspan(kHeader, length);
  return ArtNetParse::dmx;
}

ArtNetReceiver::ArtNetReceiver(const std::string& host, int port, int universe, int channel,
                               Handler handler, FrameHandler frames)
    : universe_(universe),
      watch_(channel, std::move(handler), std::move(frames)),
      udp_("Art-Net", host, port,
           [this](std::span<const std::uint8_t> datagram) { take(datagram); }) {}

void ArtNetReceiver::take(std::span<const std::uint8_t> datagram) {
  ArtDmx dmx;
  const ArtNetParse parsed = parse_artnet(datagram, dmx);
  if (parsed == ArtNetParse::malformed) {
    malformed_.fetch_add(1);
    return;
  }
  if (parsed == ArtNetParse::other || dmx.universe != universe_) {
    ignored_.fetch_add(1);
    return;
  }
  watch_.take(dmx.data);
}

}  // namespace animrt
