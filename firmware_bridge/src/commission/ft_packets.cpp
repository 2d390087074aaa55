#include "ft_packets.hpp"

#include <algorithm>
#include <array>

#include "exchange.hpp"

namespace animrt::commission::ft_detail {

using std::chrono::microseconds;

Statuses decode(std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> sent) {
  Statuses out;
  // An adapter's echo of the instruction comes first: not an answer.
  std::size_t begin = 0;
  if (bytes.size() >= sent.size() && std::equal(sent.begin(), sent.end(), bytes.begin())) {
    begin = sent.size();
  }
  out.bytes = bytes.size() - begin;
  for (std::size_t i = begin; i + 2 < bytes.size(); ++i) {
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xFF && bytes[i + 2] != 0xFF) {
      out.header_ids.insert(bytes[i + 2]);
    }
  }
  ft::Decoder decoder;
  std::size_t fed = 0;
  for (;;) {
    fed += decoder.feed(bytes.subspan(fed));
    ft::Packet packet;
    const ft::DecodeResult r = decoder.next(packet);
    if (r == ft::DecodeResult::packet) {
      if (std::equal(packet.raw.begin(), packet.raw.end(), sent.begin(), sent.end())) continue;
      out.packets.push_back(
          {packet.id, packet.code,
           std::vector<std::uint8_t>(packet.params.begin(), packet.params.end())});
      continue;
    }
    if (r == ft::DecodeResult::bad_checksum || r == ft::DecodeResult::malformed) {
      ++out.damaged;
      continue;
    }
    if (fed >= bytes.size()) break;
    decoder.reset();
  }
  if (decoder.buffered() > 0) ++out.damaged;
  return out;
}

Statuses transact(ByteTransport& line, std::uint8_t id, std::uint8_t instruction,
                  std::span<const std::uint8_t> params, std::size_t answer_bytes, int baud,
                  microseconds timeout) {
  std::array<std::uint8_t, ft::kMaxPacket> tx{};
  const std::size_t n = ft::encode_packet(id, instruction, params, tx);
  const microseconds wire = detail::wire_time(n + answer_bytes, baud);
  const detail::Wait wait{timeout + wire,
                          std::max(microseconds{2'000}, detail::wire_time(20, baud)),
                          2 * (timeout + wire) + microseconds{20'000}};
  const auto bytes = detail::exchange(line, {tx.data(), n}, wait);
  return decode(bytes, {tx.data(), n});
}

std::optional<std::vector<std::uint8_t>> read(ByteTransport& line, std::uint8_t id,
                                              std::uint8_t address, std::uint8_t length, int baud,
                                              microseconds timeout) {
  const std::uint8_t params[2] = {address, length};
  const Statuses s = transact(line, id, ft::inst::read, params, 6u + length, baud, timeout);
  for (const Status& p : s.packets) {
    if (p.id == id && p.data.size() == length) return p.data;
  }
  return std::nullopt;
}

ft::Series guess_series(std::span<const std::uint8_t> table) {
  if (table.size() <= ft::reg::max_angle_limit + 1) return ft::Series::sts;
  const auto fits = [&](ft::Series s, int max) {
    return ft::get_u16(s, &table[ft::reg::min_angle_limit]) <= max &&
           ft::get_u16(s, &table[ft::reg::max_angle_limit]) <= max;
  };
  if (!fits(ft::Series::sts, ft::kStsMaxPosition) && fits(ft::Series::scs, ft::kScsMaxPosition)) {
    return ft::Series::scs;
  }
  return ft::Series::sts;
}

}  // namespace animrt::commission::ft_detail
