#include <string>

#include "animrt/bridge/commission/serial_scan.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "ft_packets.hpp"

namespace animrt::commission {
namespace {

// A ping's status packet: FF FF ID 02 ERROR CHECKSUM.
constexpr std::size_t kPingStatusBytes = 6;

void read_ft_details(ByteTransport& line, int baud, const ScanLimits& limits, FoundDevice& d) {
  const auto table = ft_detail::read(line, static_cast<std::uint8_t>(d.id), 0,
                                     ft::reg::servo_status + 1, baud, limits.answer_timeout);
  if (!table) {
    d.note = "answered the ping but not a read of its memory table";
    return;
  }
  const std::uint8_t* t = table->data();
  namespace reg = ft::reg;
  const ft::Series series = ft_detail::guess_series(*table);
  const bool sts = series == ft::Series::sts;
  d.protocol = sts ? "feetech_sts" : "feetech_scs";
  d.model = (sts ? "STS " : "SCS ") + std::to_string(t[reg::model]) + "." +
            std::to_string(t[reg::model + 1]);
  d.firmware = std::to_string(t[reg::firmware_major]) + "." + std::to_string(t[1]);
  const std::uint16_t raw = ft::get_u16(series, t + reg::present_position);
  d.position = sts ? ft::decode_signed(raw, ft::kStsSignBit) : raw;
  d.temperature_c = t[reg::present_temperature];
  d.voltage_v = t[reg::present_voltage] / 10.0;
  d.torque_on = t[reg::torque_enable] != 0;
  d.min_limit = ft::get_u16(series, t + reg::min_angle_limit);
  d.max_limit = ft::get_u16(series, t + reg::max_angle_limit);
  d.ticks_per_rev = sts ? ft::kStsStepsPerRev : ft::kScsStepsPerRev;
  if (t[reg::servo_status] != 0) d.note = "status bits " + std::to_string(t[reg::servo_status]);
}

}  // namespace

const std::vector<int>& feetech_bauds() {
  // Baud Rate register 0..7.
  static const std::vector<int> bauds = {1'000'000, 500'000, 250'000, 128'000,
                                         115'200,   76'800,  57'600,  38'400};
  return bauds;
}

void scan_feetech(ByteTransport& line, int baud, const ScanLimits& limits, ScanResult& out) {
  int answered = 0;
  int asked = 0;
  std::size_t junk_bytes = 0;
  // Ids whose ping drew bytes that are not one clean answer from it: two
  // servos answering at once (their bytes overlap), or, when every id asked
  // draws them, a device of another protocol or baud, or noise.
  std::vector<std::pair<int, std::string>> junk;
  const int last = std::min(limits.last_id, ft::kMaxDeviceId);
  for (int id = std::max(limits.first_id, 0); id <= last; ++id) {
    ++asked;
    const ft_detail::Statuses s = ft_detail::transact(
        line, static_cast<std::uint8_t>(id), ft::inst::ping, {}, 6, baud, limits.answer_timeout);
    int from_id = 0;
    for (const ft_detail::Status& p : s.packets) from_id += p.id == id ? 1 : 0;
    const bool clean =
        from_id == 1 && s.damaged == 0 && s.bytes == s.packets.size() * (kPingStatusBytes);
    if (from_id == 0 && s.bytes == 0) continue;
    if (!clean) {
      junk_bytes += s.bytes;
      junk.emplace_back(id, from_id > 1 ? std::to_string(from_id) + " answers to one ping"
                                        : "damaged answers to a ping (overlapping replies)");
      continue;
    }
    ++answered;
    FoundDevice d;
    d.protocol = "feetech_sts";
    d.baud = baud;
    d.id = id;
    read_ft_details(line, baud, limits, d);
    out.devices.push_back(std::move(d));
  }
  if (!junk.empty() && (asked == 1 || static_cast<int>(junk.size()) < asked)) {
    for (const auto& [id, how] : junk) out.collisions.push_back({"feetech", baud, id, how});
  } else if (!junk.empty()) {
    out.garbled.push_back("feetech at " + std::to_string(baud) + ": " + std::to_string(junk_bytes) +
                          " bytes that answer no ping");
  }
  if (limits.progress) {
    limits.progress("feetech at " + std::to_string(baud) + ": " + std::to_string(answered) +
                    " id(s) answered");
  }
}

}  // namespace animrt::commission
