#include "animrt/bridge/maestro/maestro_protocol.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/device_watchdog.hpp"
#include "animrt/bridge/maestro/maestro_bus.hpp"

namespace animrt {
namespace {

constexpr std::string_view kBusKeys[] = {
    "port",          "baud",  "timeout_ms",        "serial_protocol",
    "device_number", "board", "device_watchdog_ms"};
// Serial timeout: 0.01 s resolution, at most 655.35 s.
constexpr double kTimeoutUnitMs = 10.0;
constexpr double kTimeoutMaxMs = 655350.0;
constexpr std::string_view kActuatorKeys[] = {"channel",    "device_number", "min_us",
                                              "max_us",     "neutral_us",    "rad_per_us",
                                              "deg_per_us", "speed",         "acceleration"};

// Pulse widths the board can produce: 14-bit quarter-microseconds.
constexpr double kMaxPulseUs = maestro::kMaxValue / 4.0;

struct BoardKind {
  std::string_view name;
  int channels;
  bool multiple_targets;
};
constexpr BoardKind kBoards[] = {
    {"micro6", 6, false}, {"mini12", 12, true}, {"mini18", 18, true}, {"mini24", 24, true}};

void check_pulse(const YamlNode& limit_node, double rad, const MaestroChannelOptions& ch) {
  const double us = ch.neutral_us + rad / ch.rad_per_us;
  if (us < ch.min_us - 1e-9 || us > ch.max_us + 1e-9) {
    limit_node.fail(format_number(rad_to_deg(rad)) + " deg maps to " + format_number(us) +
                    " us (neutral_us " + format_number(ch.neutral_us) + ", " +
                    format_number(rad_to_deg(ch.rad_per_us)) +
                    " deg/us), outside min_us..max_us (" + format_number(ch.min_us) + ".." +
                    format_number(ch.max_us) + ")");
  }
}

class Maestro final : public Protocol {
 public:
  std::string_view name() const override { return "maestro"; }
  std::span<const std::string_view> bus_keys() const override { return kBusKeys; }
  std::span<const std::string_view> actuator_keys() const override { return kActuatorKeys; }

  void read_bus(const YamlNode& node, BusConfig& bus) const override {
    const YamlNode port = node.at("port");
    bus.port = port.as_string();
    if (bus.port.empty()) port.fail("expected a device path such as /dev/ttyACM0, found \"\"");
    // The Maestro detects (or is set to) 300..200000 baud.
    bus.baud = 115200;
    if (auto n = node.find("baud")) bus.baud = static_cast<int>(n->as_int_in(300, 200000));
    bus.timeout_s = 0.02;
    if (auto n = node.find("timeout_ms")) {
      const double ms = n->as_double();
      if (!(ms > 0.0 && ms < 1000.0)) {
        n->fail("expected a number greater than 0 and less than 1000, found " + n->describe());
      }
      bus.timeout_s = ms / 1000.0;
    }
    MaestroBusOptions options;
    if (auto n = node.find("serial_protocol")) {
      const std::string form = n->as_string();
      if (form == "compact") {
        options.form = maestro::Form::compact;
      } else if (form == "pololu") {
        options.form = maestro::Form::pololu;
      } else {
        n->fail("expected compact or pololu, found " + n->describe());
      }
    }
    int device = maestro::kDefaultDevice;
    if (auto n = node.find("device_number")) {
      if (options.form != maestro::Form::pololu) {
        n->fail(
            "device_number needs serial_protocol: pololu (the compact protocol has no address)");
      }
      device = static_cast<int>(n->as_int_in(0, 127));
    }
    if (auto n = node.find("board")) {
      const std::string kind = n->as_string();
      bool found = false;
      for (const BoardKind& b : kBoards) {
        if (b.name == kind) {
          options.channels = b.channels;
          options.multiple_targets = b.multiple_targets;
          found = true;
        }
      }
      if (!found) n->fail("expected micro6, mini12, mini18 or mini24, found " + n->describe());
    }
    options.device = device;
    options.serial_timeout_ms = read_device_watchdog_ms(
        node, bus.loop_period_s, kTimeoutUnitMs, kTimeoutMaxMs, "serial timeout, units of 10 ms");
    bus.options = options;
  }

  std::string device_guard_note(const BusConfig& bus) const override {
    const double ms = std::any_cast<const MaestroBusOptions&>(bus.options).serial_timeout_ms;
    if (ms == 0.0) {
      return "no device-side guard (device_watchdog_ms: off): if the host dies, the servos hold "
             "their last target";
    }
    // Settings the serial protocol can neither write nor read.
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.2f", ms / 1000.0);
    return std::string(
               "the Maestro takes its serial timeout only from its settings: set Serial "
               "Settings > Timeout to ") +
           seconds +
           " s in the Maestro Control Center, and each channel's On startup or error to Off "
           "or Go to (what the servo does when the host dies)";
  }

  void read_actuator(const YamlNode& node, const JointSpec& joint, const YamlNode& limits_node,
                     const BusConfig& bus, ActuatorBinding& out) const override {
    const auto& options = std::any_cast<const MaestroBusOptions&>(bus.options);
    MaestroChannelOptions ch;
    ch.device = options.device;
    if (auto n = node.find("device_number")) {
      if (options.form != maestro::Form::pololu) {
        n->fail("device_number needs serial_protocol: pololu on bus " + bus.name);
      }
      ch.device = static_cast<int>(n->as_int_in(0, 127));
    }
    const YamlNode channel = node.at("channel");
    ch.channel = static_cast<int>(channel.as_int());
    if (ch.channel < 0 || ch.channel >= options.channels) {
      channel.fail("expected a channel from 0 to " + std::to_string(options.channels - 1) +
                   " on this board, found " + channel.describe());
    }
    for (const auto& other : bus.actuators) {
      const auto& o = std::any_cast<const MaestroChannelOptions&>(other.options);
      if (o.channel == ch.channel && o.device == ch.device) {
        channel.fail("channel " + std::to_string(ch.channel) + " is already used by joint " +
                     other.joint + " on bus " + bus.name);
      }
    }
    if (auto n = node.find("min_us")) ch.min_us = n->as_double_in(0.25, kMaxPulseUs);
    const YamlNode max_node = node.find("max_us") ? node.at("max_us") : node;
    if (auto n = node.find("max_us")) ch.max_us = n->as_double_in(0.25, kMaxPulseUs);
    if (!(ch.max_us > ch.min_us)) {
      max_node.fail("expected max_us greater than min_us (" + format_number(ch.min_us) +
                    "), found " + format_number(ch.max_us));
    }
    if (auto n = node.find("neutral_us")) {
      ch.neutral_us = n->as_double();
      if (ch.neutral_us < ch.min_us || ch.neutral_us > ch.max_us) {
        n->fail("expected neutral_us within min_us..max_us (" + format_number(ch.min_us) + ".." +
                format_number(ch.max_us) + "), found " + n->describe());
      }
    } else if (ch.neutral_us < ch.min_us || ch.neutral_us > ch.max_us) {
      node.fail("the default neutral_us 1500 is outside min_us..max_us; set neutral_us");
    }
    const auto per_rad = node.find("rad_per_us");
    const auto per_deg = node.find("deg_per_us");
    if (per_rad && per_deg) per_deg->fail("give either rad_per_us or deg_per_us, not both");
    if (!per_rad && !per_deg) {
      node.fail(
          "missing key rad_per_us or deg_per_us (the servo's angle per microsecond of pulse, "
          "negative for a mirrored servo)");
    }
    const YamlNode& scale = per_rad ? *per_rad : *per_deg;
    const double value = scale.as_double();
    // A hobby servo turns roughly 0.05..0.2 deg per microsecond of pulse.
    const double deg_per_us = std::abs(per_rad ? rad_to_deg(value) : value);
    if (!(std::isfinite(value) && deg_per_us >= 0.001 && deg_per_us <= 10.0)) {
      scale.fail("expected a magnitude from " +
                 std::string(per_rad ? "1.745e-05 to 0.1745 rad/us" : "0.001 to 10 deg/us") +
                 " (negative for a mirrored servo), found " + scale.describe());
    }
    ch.rad_per_us = per_rad ? value : deg_to_rad(value);
    if (auto n = node.find("speed"))
      ch.speed = static_cast<int>(n->as_int_in(0, maestro::kMaxValue));
    if (auto n = node.find("acceleration"))
      ch.acceleration = static_cast<int>(n->as_int_in(0, 255));

    check_pulse(limits_node.at("min_deg"), joint.limits.min_position, ch);
    check_pulse(limits_node.at("max_deg"), joint.limits.max_position, ch);

    // Ticks are quarter-microseconds.
    out.device_id =
        options.form == maestro::Form::compact ? ch.channel : 100 * ch.device + ch.channel;
    out.zero_ticks = static_cast<std::int32_t>(std::lround(ch.neutral_us * 4.0));
    out.ticks_per_rad = 4.0 / std::abs(ch.rad_per_us);
    out.direction = ch.rad_per_us > 0 ? 1 : -1;
    out.options = ch;
  }

  // Per channel a Set Target (4 bytes compact, 6 Pololu) and a Get Position
  // (2 or 4 bytes) with its 2-byte answer, at 10 bits per byte.
  double wire_bits_per_cycle(const BusConfig& bus) const override {
    const auto& options = std::any_cast<const MaestroBusOptions&>(bus.options);
    const double per_channel = options.form == maestro::Form::pololu ? 12.0 : 8.0;
    return 10.0 * per_channel * static_cast<double>(bus.actuators.size());
  }

  std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) const override {
    return std::make_unique<MaestroBus>(config, open_bus_serial(config));
  }
};

}  // namespace

const Protocol& maestro_protocol() {
  static const Maestro protocol;
  return protocol;
}

}  // namespace animrt
