#include "animrt/runtime/artnet_receiver.hpp"

#include <algorithm>
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
  // Art-Net 4 asks receivers to ignore versions before 14.
  if (((packet[10] << 8) | packet[11]) < 14) return ArtNetParse::malformed;
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
  out.sequence = packet[12];
  out.data = packet.subspan(kHeader, length);
  return ArtNetParse::dmx;
}

ArtNetSources::Verdict ArtNetSources::take(const UdpSender& from, const ArtDmx& dmx, double now_s) {
  Source* source = nullptr;
  Source* free = nullptr;
  for (Source& s : sources_) {
    if (s.used && now_s - s.seen_s > kForgetS) s.used = false;
    if (s.used && s.address == from.address) source = &s;
    if (!s.used && free == nullptr) free = &s;
  }
  if (source == nullptr) {
    if (free == nullptr) return Verdict::third_source;
    *free = Source{from.address, {}, 0, 0, now_s, true};
    source = free;
  } else if (dmx.sequence != 0 && source->sequence != 0) {
    // 1 to 19 behind the source's last came late, overtaken on the way (a
    // sender's counter runs 1-255 and wraps past 0). The same number again
    // is a sender that does not count: taken.
    int behind = source->sequence - dmx.sequence;
    if (behind < 0) behind += 255;
    if (behind >= 1 && behind < 20) return Verdict::out_of_sequence;
  }
  source->sequence = dmx.sequence;
  source->seen_s = now_s;
  source->length = dmx.data.size();
  std::copy(dmx.data.begin(), dmx.data.end(), source->levels.begin());
  std::fill(source->levels.begin() + static_cast<long>(dmx.data.size()), source->levels.end(), 0);
  merged_length_ = 0;
  merged_.fill(0);
  for (const Source& s : sources_) {
    if (!s.used) continue;
    merged_length_ = std::max(merged_length_, s.length);
    for (std::size_t c = 0; c < s.length; ++c) merged_[c] = std::max(merged_[c], s.levels[c]);
  }
  return Verdict::output;
}

ArtNetReceiver::ArtNetReceiver(const std::string& host, int port, int universe, int channel,
                               Handler handler, FrameHandler frames)
    : universe_(universe),
      watch_(channel, std::move(handler), std::move(frames)),
      udp_("Art-Net", host, port,
           [this](std::span<const std::uint8_t> datagram, const UdpSender& from) {
             take(datagram, from);
           }) {}

void ArtNetReceiver::take(std::span<const std::uint8_t> datagram, const UdpSender& from) {
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
  const double now_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
  const ArtNetSources::Verdict verdict = sources_.take(from, dmx, now_s);
  if (verdict == ArtNetSources::Verdict::out_of_sequence) out_of_sequence_.fetch_add(1);
  if (verdict == ArtNetSources::Verdict::third_source) ignored_.fetch_add(1);
  if (verdict != ArtNetSources::Verdict::output) return;
  watch_.take(sources_.merged());
}

}  // namespace animrt
