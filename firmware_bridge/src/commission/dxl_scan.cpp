#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>

#include "animrt/bridge/commission/serial_scan.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
#include "dxl_packets.hpp"
#include "exchange.hpp"

namespace animrt::commission {
namespace {

using std::chrono::microseconds;

// How long a broadcast ping's answers may take: every device answers in
// turn (by id), so the wait grows with the highest id asked: each answer's
// bytes on the wire plus a slot of about 3 ms, and some slack.
microseconds broadcast_window(int last_id, int baud, microseconds timeout) {
  const std::size_t slots = static_cast<std::size_t>(std::max(last_id, 0) + 1);
  return detail::wire_time(dxl_detail::kPingStatusBytes * slots, baud) +
         microseconds{3'000} * static_cast<long>(slots) + timeout;
}

std::string model_name(std::uint16_t number) {
  if (const dxl::XModel* m = dxl::find_x_model(number)) {
    return std::string(m->name) + " (" + std::to_string(number) + ")";
  }
  return "model " + std::to_string(number);
}

void read_dxl_details(ByteTransport& line, int baud, const ScanLimits& limits, FoundDevice& d) {
  const auto table = dxl_detail::read(line, static_cast<std::uint8_t>(d.id), 0,
                                      dxl_detail::kScanTableBytes, baud, limits.answer_timeout);
  if (!table) {
    d.note = "answered the ping but not a read of its control table";
    return;
  }
  const std::uint8_t* t = table->data();
  namespace x = dxl::xreg;
  d.model = model_name(dxl::get_u16(t + x::model_number));
  d.firmware = std::to_string(t[x::firmware_version]);
  d.position = static_cast<std::int32_t>(dxl::get_u32(t + x::present_position));
  d.temperature_c = t[x::present_temperature];
  d.voltage_v = dxl::get_u16(t + dxl_detail::kPresentInputVoltage) / 10.0;
  d.torque_on = t[x::torque_enable] != 0;
  d.min_limit = static_cast<std::int32_t>(dxl::get_u32(t + x::min_position_limit));
  d.max_limit = static_cast<std::int32_t>(dxl::get_u32(t + x::max_position_limit));
  d.ticks_per_rev = 4096.0;
  const std::uint8_t mode = t[x::operating_mode];
  if (mode != 3) d.note = "operating mode " + dxl_detail::mode_name(mode);
  d.multi_turn = mode == dxl::kExtendedPositionMode;
  if (t[x::hardware_error_status] != 0) {
    if (!d.note.empty()) d.note += "; ";
    d.note += "hardware error status " + std::to_string(t[x::hardware_error_status]);
  }
}

}  // namespace

const std::vector<int>& dynamixel_bauds() {
  static const std::vector<int> bauds = {9600,      57600,     115200,    1'000'000,
                                         2'000'000, 3'000'000, 4'000'000, 4'500'000};
  return bauds;
}

void scan_dynamixel(ByteTransport& line, int baud, const ScanLimits& limits, ScanResult& out) {
  std::array<std::uint8_t, 16> ping{};
  const std::size_t n = dxl::encode_ping(dxl::kBroadcastId, ping);
  const microseconds window = broadcast_window(limits.last_id, baud, limits.answer_timeout);
  const std::vector<std::uint8_t> bytes =
      detail::exchange(line, {ping.data(), n}, {window, window, window});
  const dxl_detail::Statuses answers = dxl_detail::decode(bytes);

  std::map<int, int> count;  // id -> clean answers
  for (const dxl_detail::Status& s : answers.packets) {
    if (s.id < limits.first_id || s.id > limits.last_id) continue;
    ++count[s.id];
  }
  std::set<int> collided;
  for (const auto& [id, answered] : count) {
    if (answered > 1) {
      out.collisions.push_back(
          {"dynamixel2", baud, id, std::to_string(answered) + " answers to one broadcast ping"});
      collided.insert(id);
    }
  }
  // A header whose packet did not check out: overlapping answers of servos
  // that share the id (or noise; the user is told to plug one at a time).
  if (answers.damaged > 0) {
    for (int id : answers.header_ids) {
      if (collided.count(id) != 0 || id < limits.first_id || id > limits.last_id) continue;
      out.collisions.push_back(
          {"dynamixel2", baud, id, "damaged answers to a broadcast ping (overlapping replies)"});
      collided.insert(id);
    }
  }
  if (answers.damaged > 0 || answers.stray > 0) {
    // Damaged answers: ask each id alone, so that replies overlapping in
    // one slot show at their id. Junk for every id asked is no collision
    // but a device of another protocol or baud, or noise.
    std::vector<int> junk;
    int asked = 0;
    for (int id = limits.first_id; id <= std::min(limits.last_id, 252); ++id) {
      if (count.count(id) != 0 || collided.count(id) != 0) continue;
      ++asked;
      const dxl_detail::Statuses s =
          dxl_detail::ping(line, static_cast<std::uint8_t>(id), baud, limits.answer_timeout);
      const auto from_id = std::count_if(s.packets.begin(), s.packets.end(),
                                         [id](const dxl_detail::Status& p) { return p.id == id; });
      const bool damaged = s.damaged > 0 || s.stray > 0;
      if (from_id == 1 && !damaged) {
        count[id] = 1;
      } else if (from_id > 1 || damaged) {
        junk.push_back(id);
      }
    }
    if (!junk.empty() && (asked == 1 || static_cast<int>(junk.size()) < asked)) {
      for (int id : junk) {
        out.collisions.push_back(
            {"dynamixel2", baud, id, "damaged answers to a unicast ping (overlapping replies)"});
        collided.insert(id);
      }
    } else if (collided.empty() && count.empty()) {
      out.garbled.push_back("dynamixel2 at " + std::to_string(baud) + ": " +
                            std::to_string(bytes.size()) +
                            " bytes that are no status packet answered the broadcast ping");
    }
  }
  for (const auto& [id, answered] : count) {
    if (collided.count(id) != 0) continue;
    FoundDevice d;
    d.protocol = "dynamixel2";
    d.baud = baud;
    d.id = id;
    read_dxl_details(line, baud, limits, d);
    out.devices.push_back(std::move(d));
  }
  if (limits.progress) {
    limits.progress("dynamixel2 at " + std::to_string(baud) + ": " + std::to_string(count.size()) +
                    " id(s) answered");
  }
}

}  // namespace animrt::commission
