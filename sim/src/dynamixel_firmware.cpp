#include "animrt/sim/dynamixel_firmware.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "animrt/core/error.hpp"

namespace animrt::sim {
namespace {

using dxl::StatusError;
namespace inst = dxl::inst;

constexpr int kMaxDeviceId = 252;
constexpr std::uint8_t kReplyPingAndRead = 1;  // Status Return Level
constexpr std::uint8_t kReplyAll = 2;
constexpr std::uint8_t kBroadcastResetAllIgnored = 42;  // firmware version

std::uint16_t u16_at(std::span<const std::uint8_t> p, std::size_t i) { return dxl::get_u16(&p[i]); }

}  // namespace

bool may_answer(const dxl::Packet& packet) {
  if (packet.instruction == inst::status) return false;
  if (packet.id != dxl::kBroadcastId) return true;
  return packet.instruction == inst::ping || packet.instruction == inst::sync_read ||
         packet.instruction == inst::bulk_read || packet.instruction == inst::fast_sync_read ||
         packet.instruction == inst::fast_bulk_read;
}

DynamixelFirmware::DynamixelFirmware(const BusConfig& config, Nanos now, JointPhysics* physics) {
  servos_.reserve(config.actuators.size());
  by_id_.reserve(config.actuators.size());
  fast_entries_.reserve(256);
  for (const ActuatorBinding& binding : config.actuators) {
    if (binding.device_id < 0 || binding.device_id > kMaxDeviceId) {
      throw InputError(config.where, "device_id",
                       "Dynamixel id " + std::to_string(binding.device_id) + " of joint '" +
                           elide(binding.joint) + "' is outside 0..252");
    }
    if (find_configured(binding.device_id) != nullptr) {
      throw InputError(config.where, "device_id",
                       "Dynamixel id " + std::to_string(binding.device_id) +
                           " is used twice on bus '" + elide(config.name) + "'");
    }
    servos_.emplace_back(binding, config.sim, config.baud, now, physics);
  }
}

DynamixelServo* DynamixelFirmware::find_configured(int device_id) {
  for (DynamixelServo& s : servos_) {
    if (s.device_id() == device_id) return &s;
  }
  return nullptr;
}

const DynamixelServo* DynamixelFirmware::find_configured(int device_id) const {
  for (const DynamixelServo& s : servos_) {
    if (s.device_id() == device_id) return &s;
  }
  return nullptr;
}

DynamixelServo* DynamixelFirmware::target(std::uint8_t id) {
  for (DynamixelServo& s : servos_) {
    if (s.id() == id && s.responding()) return &s;
  }
  return nullptr;
}

template <class Act>
void DynamixelFirmware::for_id(std::uint8_t id, Answers& out, Act&& act) {
  const std::size_t first = out.list.size();
  for (DynamixelServo& s : servos_) {
    if (s.id() == id && s.responding()) act(s);
  }
  collide(out, first);
}

void DynamixelFirmware::answer(const DynamixelServo& servo, StatusError error,
                               std::span<const std::uint8_t> data, Answers& out) const {
  const std::size_t offset = out.bytes.size();
  out.bytes.resize(offset + dxl::kMaxPacket);
  const std::size_t n = dxl::encode_status(servo.id(), servo.status_error(error), data,
                                           {out.bytes.data() + offset, dxl::kMaxPacket});
  out.bytes.resize(offset + n);
  if (n > 0) out.list.push_back({offset, n, servo.return_delay_us(), servo.take_answer_delay()});
}

void DynamixelFirmware::answer_read(const DynamixelServo& servo, std::uint16_t address,
                                    std::uint16_t length, Answers& out) const {
  if (servo.status_return_level() < kReplyPingAndRead) return;
  std::array<std::uint8_t, dxl::xreg::table_size> data{};
  const StatusError error =
      length <= data.size() ? servo.read(address, length, data) : StatusError::access;
  const std::size_t n = error == StatusError::none ? length : 0;
  answer(servo, error, {data.data(), n}, out);
}

void DynamixelFirmware::answer_fast(std::span<const dxl::BulkReadEntry> entries, Answers& out) {
  std::size_t data_bytes = 0;
  for (const dxl::BulkReadEntry& e : entries) data_bytes += e.length;
  const std::size_t size = dxl::fast_status_size(entries.size(), data_bytes);
  if (size > dxl::kMaxPacket) return;  // no LEN the devices could agree on: silence
  const std::size_t offset = out.bytes.size();
  out.bytes.resize(offset + size);
  dxl::FastStatusWriter w({out.bytes.data() + offset, size}, entries.size(), data_bytes);
  std::array<std::uint8_t, dxl::kMaxPacket> data{};
  for (const dxl::BulkReadEntry& e : entries) {
    const DynamixelServo* s = target(e.id);
    // A servo that is absent, silent (Status Return Level 0) or too old for
    // fast read leaves its slice out; the others still answer in turn.
    if (s == nullptr || s->status_return_level() < kReplyPingAndRead || !s->fast_read()) continue;
    const std::size_t begin = w.size();
    if (begin == 0) w.header();
    std::fill_n(data.begin(), e.length, std::uint8_t{0});
    const StatusError error = s->read(e.address, e.length, {data.data(), e.length});
    // On an error the slice keeps its length (the packet's LEN counted it),
    // with zeros for data.
    if (error != StatusError::none) std::fill_n(data.begin(), e.length, std::uint8_t{0});
    w.slice(s->status_error(error), s->id(), {data.data(), e.length});
    out.list.push_back(
        {offset + begin, w.size() - begin, s->return_delay_us(), s->take_answer_delay()});
  }
  out.bytes.resize(offset + w.size());
}

void DynamixelFirmware::ping(const dxl::Packet& packet, Answers& out) {
  // Answered whatever the Status Return Level; to a broadcast, every servo
  // in ID order, those sharing an ID at once.
  by_id_.clear();
  for (DynamixelServo& s : servos_) {
    if (s.responding() && (packet.id == dxl::kBroadcastId || s.id() == packet.id)) {
      by_id_.push_back(&s);
    }
  }
  std::sort(by_id_.begin(), by_id_.end(),
            [](const DynamixelServo* a, const DynamixelServo* b) { return a->id() < b->id(); });
  std::size_t first = out.list.size();
  for (std::size_t k = 0; k < by_id_.size(); ++k) {
    const DynamixelServo* s = by_id_[k];
    if (k > 0 && s->id() != by_id_[k - 1]->id()) {
      collide(out, first);  // the servos before answered in one slot
      first = out.list.size();
    }
    std::array<std::uint8_t, 3> info{};
    s->read(dxl::xreg::model_number, 2, info);
    s->read(dxl::xreg::firmware_version, 1, std::span(info).subspan(2));
    answer(*s, StatusError::none, info, out);
  }
  collide(out, first);
}

void DynamixelFirmware::factory_reset(const dxl::Packet& packet, Nanos now, Answers& out) {
  // Option 0xFF resets everything, 0x01 all but the ID, 0x02 all but the ID
  // and the baud rate. The status packet leaves first, with the old ID at
  // the old baud. From firmware 42 on a broadcast 0xFF is ignored (every
  // servo would become ID 1).
  const std::span<const std::uint8_t> p = packet.params;
  const bool broadcast = packet.id == dxl::kBroadcastId;
  const std::uint8_t option = p.size() == 1 ? p[0] : 0;
  const bool known = option == 0xFF || option == 0x01 || option == 0x02;
  const StatusError error = p.size() != 1 ? StatusError::data_length
                            : !known      ? StatusError::data_range
                                          : StatusError::none;
  auto act = [&](DynamixelServo& s) {
    if (broadcast && option == 0xFF && s.firmware_version() >= kBroadcastResetAllIgnored) return;
    if (!broadcast && s.status_return_level() >= kReplyAll) answer(s, error, {}, out);
    if (error == StatusError::none) s.factory_reset(option, now);
  };
  if (!broadcast) {
    for_id(packet.id, out, act);
    return;
  }
  for (DynamixelServo& s : servos_) {
    if (s.responding()) act(s);
  }
}

void DynamixelFirmware::handle(const dxl::Packet& packet, Nanos now, Answers& out, int line_baud) {
  for (DynamixelServo& s : servos_) {
    s.advance(now);
    s.set_hearing(line_baud == 0 || s.baud() == line_baud);
  }
  const std::span<const std::uint8_t> p = packet.params;
  const bool broadcast = packet.id == dxl::kBroadcastId;

  // Unicast instructions: the addressed servo acts and answers per its
  // Status Return Level; broadcast ones act on every servo, silently.
  auto each_target = [&](auto&& act) {
    if (broadcast) {
      for (DynamixelServo& s : servos_) {
        if (s.responding()) act(s);
      }
    } else {
      for_id(packet.id, out, act);
    }
  };
  // `level` is the Status Return Level when the packet arrived: a write that
  // changes it is still answered as before.
  auto reply = [&](const DynamixelServo& s, std::uint8_t level, StatusError error) {
    if (!broadcast && level >= kReplyAll) answer(s, error, {}, out);
  };

  switch (packet.instruction) {
    case inst::ping:
      ping(packet, out);
      break;
    case inst::read:
      if (broadcast) break;  // the manual: no status for a broadcast Read
      for_id(packet.id, out, [&](DynamixelServo& s) {
        if (p.size() != 4) {
          if (s.status_return_level() >= kReplyPingAndRead) {
            answer(s, StatusError::data_length, {}, out);
          }
        } else {
          answer_read(s, u16_at(p, 0), u16_at(p, 2), out);
        }
      });
      break;
    case inst::write:
    case inst::reg_write:
      each_target([&](DynamixelServo& s) {
        const std::uint8_t level = s.status_return_level();
        StatusError error = StatusError::data_length;
        if (p.size() >= 3) {
          error = packet.instruction == inst::write ? s.write(u16_at(p, 0), p.subspan(2))
                                                    : s.reg_write(u16_at(p, 0), p.subspan(2));
        }
        reply(s, level, error);
      });
      break;
    case inst::action:
      each_target([&](DynamixelServo& s) {
        const std::uint8_t level = s.status_return_level();
        reply(s, level, s.action());
      });
      break;
    case inst::reboot:
      // The status packet goes out before the servo restarts.
      each_target([&](DynamixelServo& s) {
        reply(s, s.status_return_level(), StatusError::none);
        s.reboot(now);
      });
      break;
    case inst::sync_read:
      if (!broadcast || p.size() < 5) break;
      for (std::uint8_t id : p.subspan(4)) {
        for_id(id, out,
               [&](DynamixelServo& s) { answer_read(s, u16_at(p, 0), u16_at(p, 2), out); });
      }
      break;
    case inst::fast_sync_read: {
      if (!broadcast || p.size() < 5) break;
      fast_entries_.clear();
      for (std::uint8_t id : p.subspan(4))
        fast_entries_.push_back({id, u16_at(p, 0), u16_at(p, 2)});
      answer_fast(fast_entries_, out);
      break;
    }
    case inst::fast_bulk_read: {
      if (!broadcast || p.empty() || p.size() % 5 != 0) break;
      fast_entries_.clear();
      for (std::size_t i = 0; i < p.size(); i += 5) {
        fast_entries_.push_back({p[i], u16_at(p, i + 1), u16_at(p, i + 3)});
      }
      answer_fast(fast_entries_, out);
      break;
    }
    case inst::sync_write: {
      if (!broadcast || p.size() < 4) break;
      const std::size_t length = u16_at(p, 2);
      const std::span<const std::uint8_t> blocks = p.subspan(4);
      if (length == 0 || blocks.size() % (length + 1) != 0) break;  // malformed: ignored
      for (std::size_t i = 0; i < blocks.size(); i += length + 1) {
        for_id(blocks[i], out,
               [&](DynamixelServo& s) { s.write(u16_at(p, 0), blocks.subspan(i + 1, length)); });
      }
      break;
    }
    case inst::bulk_read:
      if (!broadcast || p.empty() || p.size() % 5 != 0) break;
      for (std::size_t i = 0; i < p.size(); i += 5) {
        for_id(p[i], out,
               [&](DynamixelServo& s) { answer_read(s, u16_at(p, i + 1), u16_at(p, i + 3), out); });
      }
      break;
    case inst::bulk_write: {
      if (!broadcast) break;
      // Check the whole layout first: a truncated packet changes nothing.
      std::size_t i = 0;
      while (i + 5 <= p.size()) i += 5 + u16_at(p, i + 3);
      if (i != p.size() || p.empty()) break;
      for (i = 0; i < p.size(); i += 5 + u16_at(p, i + 3)) {
        for_id(p[i], out, [&](DynamixelServo& s) {
          s.write(u16_at(p, i + 1), p.subspan(i + 5, u16_at(p, i + 3)));
        });
      }
      break;
    }
    case inst::factory_reset:
      factory_reset(packet, now, out);
      break;
    case inst::status:
      break;  // another device's answer: not for us
    default:
      // Clear and anything unknown.
      each_target(
          [&](DynamixelServo& s) { reply(s, s.status_return_level(), StatusError::instruction); });
      break;
  }
  // Every instruction packet a servo takes in (its id or broadcast) feeds
  // its Bus Watchdog.
  if (packet.instruction == inst::status) return;
  for (DynamixelServo& s : servos_) {
    if (s.responding() && (broadcast || s.id() == packet.id)) s.feed_watchdog(now);
  }
}

}  // namespace animrt::sim
