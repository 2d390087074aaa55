#include "dxl_packets.hpp"

#include <algorithm>
#include <array>

#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "exchange.hpp"

namespace animrt::commission::dxl_detail {
namespace {

using std::chrono::microseconds;

struct Mode {
  const char* name;
  std::uint8_t value;
};
// Operating Mode (address 11) of the X series, from its e-manual.
constexpr Mode kModes[] = {{"current", 0},           {"velocity", 1},         {"position", 3},
                           {"extended-position", 4}, {"current-position", 5}, {"pwm", 16}};

detail::Wait unicast_wait(std::size_t out_bytes, std::size_t in_bytes, int baud,
                          microseconds timeout) {
  const microseconds wire = detail::wire_time(out_bytes + in_bytes, baud);
  return {timeout + wire, std::max(microseconds{2'000}, detail::wire_time(20, baud)),
          2 * (timeout + wire) + microseconds{20'000}};
}

}  // namespace

Statuses decode(std::span<const std::uint8_t> bytes) {
  Statuses out;
  for (std::size_t i = 0; i + 4 < bytes.size(); ++i) {
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xFF && bytes[i + 2] == 0xFD && bytes[i + 3] == 0x00 &&
        bytes[i + 4] != 0xFD) {
      // Only status headers: an instruction's echo carries its instruction
      // byte at +7, a status 0x55.
      if (i + 7 >= bytes.size() || bytes[i + 7] == dxl::inst::status) {
        out.header_ids.insert(bytes[i + 4]);
      }
    }
  }
  dxl::Decoder decoder;
  std::size_t fed = 0;
  for (;;) {
    fed += decoder.feed(bytes.subspan(fed));
    dxl::Packet packet;
    const dxl::DecodeResult r = decoder.next(packet);
    if (r == dxl::DecodeResult::packet) {
      if (packet.instruction != dxl::inst::status || packet.params.empty()) continue;
      out.packets.push_back(
          {packet.id, packet.params[0],
           std::vector<std::uint8_t>(packet.params.begin() + 1, packet.params.end())});
      continue;
    }
    if (r == dxl::DecodeResult::bad_crc || r == dxl::DecodeResult::malformed) {
      ++out.damaged;
      continue;
    }
    if (fed >= bytes.size()) break;
    decoder.reset();  // full of bytes that make no packet
  }
  // A header cut off at the end: a damaged answer too.
  if (decoder.buffered() > 0) ++out.damaged;
  out.stray = decoder.stray_bytes() + decoder.buffered();
  return out;
}

Statuses ping(ByteTransport& line, std::uint8_t id, int baud, microseconds timeout) {
  std::array<std::uint8_t, 16> tx{};
  const std::size_t n = dxl::encode_ping(id, tx);
  return decode(
      detail::exchange(line, {tx.data(), n}, unicast_wait(n, kPingStatusBytes, baud, timeout)));
}

int instruct(ByteTransport& line, std::uint8_t id, std::uint8_t instruction,
             std::span<const std::uint8_t> params, int baud, microseconds timeout, int* answers) {
  std::array<std::uint8_t, dxl::kMaxPacket> tx{};
  const std::size_t n = dxl::encode_packet(id, instruction, params, tx);
  const auto bytes = detail::exchange(line, {tx.data(), n}, unicast_wait(n, 16, baud, timeout));
  const Statuses s = decode(bytes);
  int from_id = 0;
  int error = -1;
  for (const Status& p : s.packets) {
    if (p.id != id) continue;
    ++from_id;
    error = p.error;
  }
  if (answers != nullptr) *answers = from_id + (s.damaged > 0 ? 1 : 0);
  if (from_id != 1 || s.damaged > 0) return -1;
  return error;
}

std::optional<std::vector<std::uint8_t>> read(ByteTransport& line, std::uint8_t id,
                                              std::uint16_t address, std::uint16_t length, int baud,
                                              microseconds timeout) {
  std::array<std::uint8_t, 16> tx{};
  const std::size_t n = dxl::encode_read(id, address, length, tx);
  const std::size_t answer = 11u + length;
  const auto bytes =
      detail::exchange(line, {tx.data(), n}, unicast_wait(n, answer, baud, timeout),
                       [&](std::span<const std::uint8_t> got) {
                         const Statuses s = decode(got);
                         return std::any_of(s.packets.begin(), s.packets.end(),
                                            [&](const Status& p) { return p.id == id; });
                       });
  for (const Status& p : decode(bytes).packets) {
    if (p.id != id) continue;
    if ((p.error & 0x7F) != 0 || p.data.size() != length) return std::nullopt;
    return p.data;
  }
  return std::nullopt;
}

std::string mode_name(std::uint8_t mode) {
  for (const Mode& m : kModes) {
    if (m.value == mode) return m.name;
  }
  return std::to_string(mode);
}

std::optional<std::uint8_t> mode_value(const std::string& name) {
  for (const Mode& m : kModes) {
    if (name == m.name) return m.value;
  }
  return std::nullopt;
}

std::string mode_names() {
  std::string out;
  for (const Mode& m : kModes) out += (out.empty() ? "" : ", ") + std::string(m.name);
  return out;
}

std::string describe_error(std::uint8_t error) {
  static const char* const kNames[] = {"none",
                                       "result fail",
                                       "instruction error",
                                       "CRC error",
                                       "data range error",
                                       "data length error",
                                       "data limit error",
                                       "access error"};
  const std::uint8_t number = error & 0x7F;
  std::string text = "error " + std::to_string(number);
  if (number < std::size(kNames)) text += std::string(" (") + kNames[number] + ")";
  return text;
}

}  // namespace animrt::commission::dxl_detail
