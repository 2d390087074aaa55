#include <array>
#include <string>

#include "animrt/bridge/commission/serial_scan.hpp"
#include "animrt/bridge/maestro/maestro_codec.hpp"
#include "exchange.hpp"

namespace animrt::commission {

const std::vector<int>& maestro_bauds() {
  // The Maestro's UART takes 300..200000 baud (its command port over USB
  // any); the usual settings.
  static const std::vector<int> bauds = {9600, 57600, 115200};
  return bauds;
}

bool scan_maestro(ByteTransport& line, int baud, const ScanLimits& limits, ScanResult& out) {
  std::array<std::uint8_t, 8> tx{};
  const std::size_t n = maestro::encode_get_errors({}, tx);
  const auto wire = detail::wire_time(n + 2, baud);
  const auto bytes = detail::exchange(
      line, {tx.data(), n},
      {limits.answer_timeout + wire, limits.answer_timeout, 2 * (limits.answer_timeout + wire)},
      [](std::span<const std::uint8_t> got) { return got.size() >= 2; });
  // Two bytes, and only the error register's nine bits may be set: anything
  // else is not a Maestro.
  const bool maestro = bytes.size() == 2 && (maestro::decode_answer(bytes.data()) >> 9) == 0;
  if (maestro) {
    FoundDevice d;
    d.protocol = "maestro";
    d.baud = baud;
    d.id = maestro::kDefaultDevice;
    d.model = "Maestro";
    const std::uint16_t errors = maestro::decode_answer(bytes.data());
    std::array<std::uint8_t, 8> get{};
    const std::size_t g = maestro::encode_get_position({}, 0, get);
    const auto pos = detail::exchange(
        line, {get.data(), g},
        {limits.answer_timeout + wire, limits.answer_timeout, 2 * (limits.answer_timeout + wire)},
        [](std::span<const std::uint8_t> got) { return got.size() >= 2; });
    if (pos.size() == 2) d.position = maestro::decode_answer(pos.data());
    d.note = "errors 0x" + [&] {
      char hex[8];
      std::snprintf(hex, sizeof hex, "%04X", errors);
      return std::string(hex);
    }() + "; position is channel 0 (quarter-us)";
    out.devices.push_back(std::move(d));
  } else if (!bytes.empty() && limits.progress) {
    limits.progress("maestro at " + std::to_string(baud) + ": garbage answer to Get Errors (" +
                    std::to_string(bytes.size()) + " bytes)");
  }
  if (limits.progress && maestro) limits.progress("maestro at " + std::to_string(baud) + ": found");
  return maestro;
}

}  // namespace animrt::commission
