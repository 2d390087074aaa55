#include "animrt/bridge/dynamixel/dynamixel_protocol.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/device_watchdog.hpp"
#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"

namespace animrt {
namespace {

// Ids 253..255 are reserved (254 is broadcast); an X-series servo in position
// control mode takes goal positions 0..4095.
constexpr int kMaxDeviceId = 252;
constexpr std::int64_t kMinTicks = 0;
constexpr std::int64_t kMaxTicks = 4095;
// Extended position control (multi-turn): Goal Position +-256 turns.
constexpr std::int64_t kMaxMultiTurnTicks = 1'048'575;
constexpr double kMinTicksPerRev = 16.0;
constexpr double kMaxTicksPerRev = 1e8;

// Bus Watchdog (address 98): 1..127 units of 20 ms.
constexpr double kWatchdogUnitMs = 20.0;
constexpr double kWatchdogMaxMs = 127 * kWatchdogUnitMs;

constexpr std::string_view kBusKeys[] = {
    "port", "baud", "timeout_ms", "fast_read", "model", "device_watchdog_ms", "health"};
constexpr std::string_view kActuatorKeys[] = {
    "id", "ticks_per_rev", "ticks_per_rad", "zero_ticks", "direction", "model", "multi_turn"};

std::uint16_t parse_model(const YamlNode& node) {
  if (node.is_scalar()) {
    if (const dxl::XModel* m = dxl::find_x_model(node.raw().Scalar())) return m->number;
  }
  node.fail("expected a Dynamixel X-series model (" + dxl::x_model_names() + "), found " +
            node.describe());
}

dxl::FastRead parse_fast_read(const YamlNode& node) {
  if (node.is_scalar()) {
    const std::string& s = node.raw().Scalar();
    if (s == "auto") return dxl::FastRead::automatic;
    if (s == "on") return dxl::FastRead::on;
    if (s == "off") return dxl::FastRead::off;
  }
  node.fail("expected auto, on or off, found " + node.describe());
}

dxl::HealthRead parse_health(const YamlNode& node) {
  if (node.is_scalar()) {
    const std::string& s = node.raw().Scalar();
    if (s == "off") return dxl::HealthRead::off;
    if (s == "packed") return dxl::HealthRead::packed;
    if (s == "round_robin") return dxl::HealthRead::round_robin;
  }
  node.fail("expected off, packed or round_robin, found " + node.describe());
}

int parse_direction(const YamlNode& node) {
  if (node.is_scalar()) {
    const std::string& s = node.raw().Scalar();
    if (s == "1" || s == "+1") return 1;
    if (s == "-1") return -1;
  }
  node.fail("expected 1 or -1 (-1 for a mirrored servo), found " + node.describe());
}

// A position limit must be a position the servo can be commanded to; the
// mapping is the one ActuatorBinding::to_ticks applies at run time.
void check_ticks(const YamlNode& limit_node, double rad, const ActuatorBinding& b,
                 const std::string& scale) {
  const bool multi_turn = dxl::device_options(b).multi_turn;
  const std::int64_t lo = multi_turn ? -kMaxMultiTurnTicks : kMinTicks;
  const std::int64_t hi = multi_turn ? kMaxMultiTurnTicks : kMaxTicks;
  // In double, so that absurd scales cannot overflow an integer.
  const double ticks = std::round(b.zero_ticks + b.direction * rad * b.ticks_per_rad);
  if (ticks < static_cast<double>(lo) || ticks > static_cast<double>(hi)) {
    std::ostringstream tick_text;  // whole numbers print plainly, absurd ones in e-notation
    tick_text.precision(12);
    tick_text << ticks;
    limit_node.fail(format_number(rad_to_deg(rad)) + " deg maps to tick " + tick_text.str() +
                    " (zero_ticks " + std::to_string(b.zero_ticks) + ", direction " +
                    std::to_string(b.direction) + ", " + scale + "), outside the dynamixel2 " +
                    (multi_turn ? "extended (multi_turn) position range " : "position range ") +
                    std::to_string(lo) + ".." + std::to_string(hi));
  }
}

class Dynamixel2 final : public Protocol {
 public:
  std::string_view name() const override { return "dynamixel2"; }
  std::span<const std::string_view> bus_keys() const override { return kBusKeys; }
  std::span<const std::string_view> actuator_keys() const override { return kActuatorKeys; }

  void read_bus(const YamlNode& node, BusConfig& bus) const override {
    const YamlNode port = node.at("port");
    bus.port = port.as_string();
    if (bus.port.empty()) port.fail("expected a device path such as /dev/ttyUSB0, found \"\"");
    // Dynamixel servos run at 9600 baud and up.
    if (auto n = node.find("baud")) bus.baud = static_cast<int>(n->as_int_in(9600, 10'500'000));
    if (auto n = node.find("timeout_ms")) {
      const double ms = n->as_double();
      if (!(ms > 0.0 && ms < 1000.0)) {
        n->fail("expected a number greater than 0 and less than 1000, found " + n->describe());
      }
      bus.timeout_s = ms / 1000.0;
    }
    dxl::BusOptions options;
    if (auto n = node.find("fast_read")) options.fast_read = parse_fast_read(*n);
    if (auto n = node.find("model")) options.model_number = parse_model(*n);
    if (auto n = node.find("health")) options.health = parse_health(*n);
    const double watchdog_ms = read_device_watchdog_ms(
        node, bus.loop_period_s, kWatchdogUnitMs, kWatchdogMaxMs, "Bus Watchdog, units of 20 ms");
    options.bus_watchdog = static_cast<std::uint8_t>(std::lround(watchdog_ms / kWatchdogUnitMs));
    bus.options = options;
  }

  void read_actuator(const YamlNode& node, const JointSpec& joint, const YamlNode& limits_node,
                     const BusConfig& bus, ActuatorBinding& out) const override {
    const YamlNode id_node = node.at("id");
    const std::int64_t id = id_node.as_int();
    if (id < 0 || id > kMaxDeviceId) {
      id_node.fail("expected a device id from 0 to " + std::to_string(kMaxDeviceId) +
                   " for dynamixel2, found " + id_node.describe());
    }
    out.device_id = static_cast<int>(id);
    for (const auto& other : bus.actuators) {
      if (other.device_id == id) {
        id_node.fail("device id " + std::to_string(id) + " is already used by joint " +
                     other.joint + " on bus " + bus.name);
      }
    }

    const auto per_rev = node.find("ticks_per_rev");
    const auto per_rad = node.find("ticks_per_rad");
    if (per_rev && per_rad) per_rad->fail("give either ticks_per_rev or ticks_per_rad, not both");
    std::string scale;  // for messages
    // Servos resolve from a few hundred to about a million ticks per turn.
    if (per_rad) {
      out.ticks_per_rad =
          per_rad->as_double_in(kMinTicksPerRev / (2.0 * kPi), kMaxTicksPerRev / (2.0 * kPi));
      scale = format_number(out.ticks_per_rad) + " ticks/rad";
    } else {
      const double ticks_per_rev =
          per_rev ? per_rev->as_double_in(kMinTicksPerRev, kMaxTicksPerRev) : 4096.0;
      out.ticks_per_rad = ticks_per_rev / (2.0 * kPi);
      scale = format_number(ticks_per_rev) + " ticks/rev";
    }
    if (auto n = node.find("zero_ticks")) {
      out.zero_ticks = static_cast<std::int32_t>(n->as_int_in(
          std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()));
    }
    if (auto n = node.find("direction")) out.direction = parse_direction(*n);
    dxl::DeviceOptions device;
    device.model_number = dxl::bus_options(bus).model_number;
    if (auto n = node.find("model")) device.model_number = parse_model(*n);
    if (auto n = node.find("multi_turn")) device.multi_turn = n->as_bool();
    out.options = device;

    check_ticks(limits_node.at("min_deg"), joint.limits.min_position, out, scale);
    check_ticks(limits_node.at("max_deg"), joint.limits.max_position, out, scale);
  }

  // Sync Write of 4-byte goal positions (14 + 5 N bytes), Sync Read of
  // 4-byte present positions (14 + N) and N status packets of 15 bytes, at
  // 10 bits per byte (start, 8 data, stop). With `fast_read: on` one Fast
  // Sync Read status packet (8 + 8 N) instead; `auto` may fall back to Sync
  // Read, so it is judged by the longer one.
  double wire_bits_per_cycle(const BusConfig& bus) const override {
    const bool fast = dxl::bus_options(bus).fast_read == dxl::FastRead::on;
    const dxl::HealthRead health = dxl::bus_options(bus).health;
    // Health packed: 6 more bytes per servo in the read; round robin: one
    // Read (14) and its status packet (11 + 6) per cycle.
    const std::size_t data = health == dxl::HealthRead::packed ? 10 : 4;
    const std::size_t extra = health == dxl::HealthRead::round_robin ? 31 : 0;
    return 10.0 *
           static_cast<double>(dynamixel_wire_bytes(bus.actuators.size(), fast, data) + extra);
  }
  // One Sync Read (14 + N bytes) and its answers.
  double read_wire_bits_per_cycle(const BusConfig& bus) const override {
    const bool fast = dxl::bus_options(bus).fast_read == dxl::FastRead::on;
    const std::size_t n = bus.actuators.size();
    return 10.0 * static_cast<double>(dynamixel_wire_bytes(n, fast) - (14 + 5 * n));
  }

  std::string device_guard_note(const BusConfig& bus) const override {
    if (dxl::bus_options(bus).bus_watchdog != 0) return {};
    return "no device-side guard (device_watchdog_ms: off): if the host dies, the servos hold "
           "their last goal with torque on";
  }

  std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) const override {
    return std::make_unique<DynamixelBus>(config, open_bus_serial(config));
  }
};

}  // namespace

std::size_t dynamixel_wire_bytes(std::size_t devices, bool fast_read, std::size_t read_bytes) {
  const std::size_t n = devices;
  const std::size_t write = 14 + 5 * n;
  const std::size_t read = 14 + n;
  const std::size_t answers =
      fast_read ? dxl::fast_status_size(n, read_bytes * n) : (11 + read_bytes) * n;
  return write + read + answers;
}

const Protocol& dynamixel2_protocol() {
  static const Dynamixel2 protocol;
  return protocol;
}

}  // namespace animrt
