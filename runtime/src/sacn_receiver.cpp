#include "animrt/runtime/sacn_receiver.hpp"

#include <cstring>

namespace animrt {
namespace {

constexpr std::size_t kSacnHeader = 126;  // up to and with the START code
constexpr std::uint32_t kRootData = 0x00000004;
constexpr std::uint32_t kRootExtended = 0x00000008;
constexpr std::uint32_t kFramingData = 0x00000002;
constexpr std::uint8_t kDmpSetProperty = 0x02;
constexpr std::uint8_t kDmpAddressType = 0xa1;
constexpr std::uint8_t kPreview = 0x80, kTerminated = 0x40;
// A packet whose sequence number is up to this many behind the last one
// taken is a late one (the standard's out-of-order window).
constexpr int kSequenceWindow = 20;

unsigned be16(std::span<const std::uint8_t> p, std::size_t at) {
  return (unsigned{p[at]} << 8) | p[at + 1];
}
std::uint32_t be32(std::span<const std::uint8_t> p, std::size_t at) {
  return (std::uint32_t{p[at]} << 24) | (std::uint32_t{p[at + 1]} << 16) |
         (std::uint32_t{p[at + 2]} << 8) | p[at + 3];
}
// A PDU's flags (0x7) and length (the octets from this field to the end).
bool pdu_fits(std::span<const std::uint8_t> p, std::size_t at) {
  const unsigned field = be16(p, at);
  return (field >> 12) == 0x7 && (field & 0x0fff) == p.size() - at;
}

}  // namespace

SacnParse parse_sacn(std::span<const std::uint8_t> packet, SacnDmx& out) {
  static constexpr char kId[12] = {'A', 'S', 'C', '-', 'E', '1', '.', '1', '7', 0, 0, 0};
  if (packet.size() < 22 || be16(packet, 0) != 0x0010 || be16(packet, 2) != 0 ||
      std::memcmp(packet.data() + 4, kId, sizeof kId) != 0 || !pdu_fits(packet, 16)) {
    return SacnParse::malformed;
  }
  const std::uint32_t root = be32(packet, 18);
  if (root == kRootExtended) return SacnParse::other;
  if (root != kRootData || packet.size() < kSacnHeader) return SacnParse::malformed;
  const std::size_t count = be16(packet, 123);
  if (!pdu_fits(packet, 38) || be32(packet, 40) != kFramingData || !pdu_fits(packet, 115) ||
      packet[117] != kDmpSetProperty || packet[118] != kDmpAddressType || be16(packet, 119) != 0 ||
      be16(packet, 121) != 1 || count < 1 || count > 513 || packet.size() != 125 + count) {
    return SacnParse::malformed;
  }
  const int universe = static_cast<int>(be16(packet, 113));
  if (packet[108] > 200 || universe < 1 || universe > kSacnMaxUniverse) {
    return SacnParse::malformed;
  }
  std::memcpy(out.cid.data(), packet.data() + 22, out.cid.size());
  out.priority = packet[108];
  out.sequence = packet[111];
  out.preview = (packet[112] & kPreview) != 0;
  out.terminated = (packet[112] & kTerminated) != 0;
  out.universe = universe;
  out.start_code = packet[125];
  out.data = packet.subspan(kSacnHeader);
  return SacnParse::dmx;
}

SacnSources::Source* SacnSources::find(const std::array<std::uint8_t, 16>& cid, double now_s) {
  for (Source& s : sources_) {
    if (s.used && now_s - s.seen_s > kSacnSourceLossS) s.used = false;
  }
  Source* free = nullptr;
  for (Source& s : sources_) {
    if (s.used && s.cid == cid) return &s;
    if (!s.used && free == nullptr) free = &s;
  }
  return free;  // null when every slot holds a live source: that one is not heard
}

SacnSources::Verdict SacnSources::take(const SacnDmx& packet, double now_s) {
  Source* source = find(packet.cid, now_s);
  if (source == nullptr) return Verdict::not_output;
  if (source->used) {
    const int behind = static_cast<std::int8_t>(packet.sequence - source->sequence);
    if (behind <= 0 && behind > -kSequenceWindow) return Verdict::out_of_sequence;
  } else {
    *source = Source{packet.cid, 0, 0, now_s, true};
  }
  source->sequence = packet.sequence;
  if (packet.terminated) {
    source->used = false;
    return Verdict::not_output;
  }
  if (packet.start_code != 0) return Verdict::not_output;  // e.g. per-channel priorities
  // Preview data is not live output (E1.31 6.2.6): it neither plays nor
  // takes part in the priority among sources, so a preview at 200 does not
  // silence the desk's live data at 100.
  if (packet.preview) return Verdict::not_output;
  source->priority = packet.priority;
  source->seen_s = now_s;
  // The highest priority among live sources is output; equal ones take turns.
  for (const Source& s : sources_) {
    if (s.used && s.priority > packet.priority) return Verdict::lower_priority;
  }
  return Verdict::output;
}

std::string SacnReceiver::group(int universe) {
  return "239.255." + std::to_string((universe >> 8) & 0xff) + '.' +
         std::to_string(universe & 0xff);
}

SacnReceiver::SacnReceiver(const std::string& host, int port, bool multicast, int universe,
                           int channel, Handler handler, FrameHandler frames)
    : universe_(universe), watch_(channel, std::move(handler), std::move(frames)) {
  // Sources are told apart by their CID, not their address.
  auto take = [this](std::span<const std::uint8_t> datagram, const UdpSender&) {
    this->take(datagram);
  };
  UdpOptions shared;
  shared.reuse_address = multicast;
  unicast_ = std::make_unique<UdpReceiver>("sACN", host, port, take, shared);
  if (multicast) {
    UdpOptions joined = shared;
    joined.group = group(universe);
    joined.interface = host;
    multicast_ =
        std::make_unique<UdpReceiver>("sACN", joined.group, unicast_->port(), take, joined);
  }
}

void SacnReceiver::take(std::span<const std::uint8_t> datagram) {
  SacnDmx dmx;
  const SacnParse parsed = parse_sacn(datagram, dmx);
  if (parsed == SacnParse::malformed) {
    malformed_.fetch_add(1);
    return;
  }
  if (parsed == SacnParse::other || dmx.universe != universe_) {
    ignored_.fetch_add(1);
    return;
  }
  const std::lock_guard lock(arbitration_);
  const double now_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
  const SacnSources::Verdict verdict = sources_.take(dmx, now_s);
  if (verdict == SacnSources::Verdict::out_of_sequence) out_of_sequence_.fetch_add(1);
  if (verdict != SacnSources::Verdict::output) {
    if (verdict != SacnSources::Verdict::out_of_sequence) ignored_.fetch_add(1);
    return;
  }
  watch_.take(dmx.data);
}

}  // namespace animrt
