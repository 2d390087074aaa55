// "cia402": CANopen CiA 402 drives (cyclic synchronous position) as a
// protocol module.

#include <cmath>
#include <limits>
#include <string>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/can_protocols.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "can_config.hpp"

namespace animrt {
namespace {

constexpr std::string_view kCia402BusKeys[] = {"interface",
                                               "bitrate",
                                               "timeout_ms",
                                               "heartbeat_ms",
                                               "heartbeat_timeout_ms",
                                               "device_watchdog_ms",
                                               "abort_connection",
                                               "host_node_id",
                                               "health"};

// The consumer time of 1016h is 16 bits of milliseconds.
constexpr int kMaxConsumerMs = 65535;
constexpr std::string_view kCia402ActuatorKeys[] = {"node_id",   "counts_per_rev", "zero_counts",
                                                    "direction", "temperature",    "homing"};

// deg/s (or deg/s^2) as the drive's counts, which 6099h/609Ah hold as u32.
std::uint32_t counts_of(const YamlNode& n, double counts_per_deg) {
  const double v = n.as_double();
  const double counts = std::round(v * counts_per_deg);
  if (!(v > 0.0) || !(counts >= 1.0 && counts <= 4294967295.0)) {
    n.fail("expected a number above 0 that is at least one count and fits 32 bits (" +
           format_number(1.0 / counts_per_deg) + " to " +
           format_number(4294967295.0 / counts_per_deg) + "), found " + n.describe());
  }
  return static_cast<std::uint32_t>(counts);
}

// `homing: {method, speed_dps, zero_speed_dps, acceleration_dps2, timeout_s}`.
Cia402Homing read_homing(const YamlNode& node, double counts_per_rev) {
  if (!node.is_map())
    node.fail("expected a map {method, speed_dps, ...}, found " + node.describe());
  node.allow_only({"method", "speed_dps", "zero_speed_dps", "acceleration_dps2", "timeout_s"});
  Cia402Homing h;
  const YamlNode method = node.at("method");
  const std::int64_t m = method.as_int();
  if (!((m >= 17 && m <= 30) || m == 35 || m == 37)) {
    method.fail(
        "expected a homing method of CiA 402: 17-30 (limit or home switches, no index pulse) "
        "or 35/37 (the present position), found " +
        method.describe());
  }
  h.method = static_cast<std::int8_t>(m);
  const double per_deg = counts_per_rev / 360.0;
  if (!h.on_switches()) {
    for (const char* key : {"speed_dps", "zero_speed_dps", "acceleration_dps2", "timeout_s"}) {
      if (auto n = node.find(key))
        n->fail("method " + std::to_string(m) + " homes where the drive rests and moves nothing");
    }
    return h;
  }
  h.switch_speed = counts_of(node.at("speed_dps"), per_deg);
  h.zero_speed = h.switch_speed;
  if (auto n = node.find("zero_speed_dps")) h.zero_speed = counts_of(*n, per_deg);
  if (auto n = node.find("acceleration_dps2")) h.acceleration = counts_of(*n, per_deg);
  if (auto n = node.find("timeout_s")) h.timeout_s = n->as_double_in(0.1, 3600.0);
  return h;
}

// "0x2022:0x01" (or decimal parts): a manufacturer object, 2000h to 5FFFh.
Cia402Temperature read_temperature(const YamlNode& node, const BusConfig& bus) {
  if (!node.is_map()) node.fail("expected a map {object, type, scale}, found " + node.describe());
  node.allow_only({"object", "type", "scale"});
  if (!options_of<Cia402BusOptions>(bus.options).health)
    node.fail("needs the bus's health: true (the temperature travels in the health TPDO)");
  Cia402Temperature t;
  const YamlNode object = node.at("object");
  const std::string text = object.as_string();
  const auto colon = text.find(':');
  long index = -1, sub = -1;
  try {
    std::size_t used = 0, used_sub = 0;
    if (colon != std::string::npos) {
      index = std::stol(text.substr(0, colon), &used, 0);
      sub = std::stol(text.substr(colon + 1), &used_sub, 0);
      if (used != colon || used_sub != text.size() - colon - 1) index = -1;
    }
  } catch (...) {
    index = -1;
  }
  if (index < 0x2000 || index > 0x5FFF || sub < 0 || sub > 255)
    object.fail(
        "expected a manufacturer object INDEX:SUBINDEX from 0x2000 to 0x5FFF, e.g. "
        "\"0x2022:0x01\", found " +
        object.describe());
  t.index = static_cast<std::uint16_t>(index);
  t.subindex = static_cast<std::uint8_t>(sub);
  const YamlNode type = node.at("type");
  const std::string ty = type.as_string();
  if (ty == "int8" || ty == "uint8" || ty == "int16" || ty == "uint16") {
    t.bits = ty.find("16") != std::string::npos ? 16 : 8;
    t.is_signed = ty[0] == 'i';
  } else {
    type.fail(
        "expected int8, uint8, int16 or uint16 (TPDO2 holds 16 bits beside the current "
        "and voltage), found " +
        type.describe());
  }
  if (auto n = node.find("scale")) {
    t.scale = n->as_double();
    if (!(std::isfinite(t.scale) && t.scale != 0.0))
      n->fail("expected a non-zero number (deg C per count), found " + n->describe());
  }
  return t;
}

class Cia402 final : public Protocol {
 public:
  std::string_view name() const override { return "cia402"; }
  bool shares_port() const override { return true; }
  std::span<const std::string_view> bus_keys() const override { return kCia402BusKeys; }
  std::span<const std::string_view> actuator_keys() const override { return kCia402ActuatorKeys; }

  void read_bus(const YamlNode& node, BusConfig& bus) const override {
    can_config::read_common_bus(node, bus);
    Cia402BusOptions options;
    if (auto n = node.find("heartbeat_ms"))
      options.heartbeat_ms = static_cast<int>(n->as_int_in(1, 65535));
    options.heartbeat_timeout_ms = 3 * options.heartbeat_ms;
    if (auto n = node.find("heartbeat_timeout_ms")) {
      options.heartbeat_timeout_ms = static_cast<int>(n->as_int_in(1, 655350));
      if (options.heartbeat_timeout_ms <= options.heartbeat_ms) {
        n->fail("expected more than heartbeat_ms (" + std::to_string(options.heartbeat_ms) +
                "), found " + n->describe());
      }
    }
    options.device_watchdog_ms =
        can_config::read_device_watchdog(node, bus, kMaxConsumerMs, "CiA 402 consumer time");
    if (auto n = node.find("abort_connection")) {
      const std::string s = n->is_scalar() ? n->raw().Scalar() : "";
      if (s == "quick_stop") {
        options.abort_connection = AbortConnection::quick_stop;
      } else if (s == "disable_voltage") {
        options.abort_connection = AbortConnection::disable_voltage;
      } else if (s == "fault") {
        options.abort_connection = AbortConnection::fault;
      } else {
        n->fail(
            "expected quick_stop, disable_voltage or fault (the drive's reaction to a "
            "missed host heartbeat, object 6007h), found " +
            n->describe());
      }
    }
    if (auto n = node.find("host_node_id")) {
      options.host_node_id = static_cast<int>(n->as_int_in(1, canopen::kMaxNodeId));
    }
    if (auto n = node.find("health")) options.health = n->as_bool();
    bus.options = options;
  }

  void read_actuator(const YamlNode& node, const JointSpec& joint, const YamlNode& limits_node,
                     const BusConfig& bus, ActuatorBinding& out) const override {
    const YamlNode id_node = node.at("node_id");
    const std::int64_t id = id_node.as_int();
    if (id < 1 || id > canopen::kMaxNodeId) {
      id_node.fail("expected a CANopen node id from 1 to 127, found " + id_node.describe());
    }
    for (const auto& other : bus.actuators) {
      if (other.device_id == id) {
        id_node.fail("node id " + std::to_string(id) + " is already used by joint " + other.joint +
                     " on bus " + bus.name);
      }
    }
    const int host = options_of<Cia402BusOptions>(bus.options).host_node_id;
    if (id == host) {
      id_node.fail("node id " + std::to_string(id) + " is the host's (bus " + bus.name +
                   " host_node_id, default 127): its heartbeats would be taken for the drive's");
    }
    out.device_id = static_cast<int>(id);
    double counts_per_rev = 4096.0;
    // Encoders resolve from a few counts to about 2^31 counts per turn.
    if (auto n = node.find("counts_per_rev")) counts_per_rev = n->as_double_in(4.0, 2147483648.0);
    out.ticks_per_rad = counts_per_rev / (2.0 * kPi);
    out.zero_ticks = 0;
    if (auto n = node.find("zero_counts")) {
      out.zero_ticks = static_cast<std::int32_t>(n->as_int_in(
          std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()));
    }
    if (auto n = node.find("direction")) out.direction = can_config::read_direction(*n);
    Cia402JointOptions joint_options;
    if (auto n = node.find("temperature")) {
      joint_options.has_temperature = true;
      joint_options.temperature = read_temperature(*n, bus);
    }
    if (auto n = node.find("homing")) joint_options.homing = read_homing(*n, counts_per_rev);
    out.options = joint_options;
    const auto check = [&](const char* key, double rad) {
      const double counts = std::round(out.zero_ticks + out.direction * rad * out.ticks_per_rad);
      if (counts < std::numeric_limits<std::int32_t>::min() ||
          counts > std::numeric_limits<std::int32_t>::max()) {
        limits_node.at(key).fail(format_number(rad_to_deg(rad)) +
                                 " deg maps outside the 32-bit target position range");
      }
    };
    check("min_deg", joint.limits.min_position);
    check("max_deg", joint.limits.max_position);
  }

  // One SYNC (no data), the host heartbeat, and per drive an RPDO and a TPDO of 6 data bytes;
  // a CAN 2.0A frame is 47 + 8 per data byte bits, plus worst-case bit
  // stuffing (one per four bits of the stuffed span).
  double wire_bits_per_cycle(const BusConfig& bus) const override {
    const auto frame = [](double data_bytes) {
      const double stuffed = 34.0 + 8.0 * data_bytes;
      return 47.0 + 8.0 * data_bytes + std::floor((stuffed - 1.0) / 4.0);
    };
    // The host's heartbeat (1 byte) comes at most once a cycle.
    const bool heartbeat = options_of<Cia402BusOptions>(bus.options).device_watchdog_ms > 0;
    return frame(0) + (heartbeat ? frame(1) : 0.0) +
           2.0 * frame(6) * static_cast<double>(bus.actuators.size());
  }

  // With the guard on the drives are set at activate: nothing to say.
  std::string device_guard_note(const BusConfig& bus) const override {
    if (options_of<Cia402BusOptions>(bus.options).device_watchdog_ms != 0) return {};
    return "no device-side guard (device_watchdog_ms: off): if the host dies, the drives stay "
           "in Operation Enabled at their last target";
  }

  std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) const override {
    return std::make_unique<Cia402Bus>(config, open_bus_can(config));
  }
};

}  // namespace

const Protocol& cia402_protocol() {
  static const Cia402 protocol;
  return protocol;
}

}  // namespace animrt
