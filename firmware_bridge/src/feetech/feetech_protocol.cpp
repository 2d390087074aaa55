#include "animrt/bridge/feetech/feetech_protocol.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/device_watchdog.hpp"
#include "animrt/bridge/feetech/feetech_bus.hpp"

namespace animrt {
namespace {

// The baud rates a Feetech servo can be set to (Baud Rate register 0..7).
constexpr int kBauds[] = {1'000'000, 500'000, 250'000, 128'000, 115'200, 76'800, 57'600, 38'400};
constexpr double kMinTicksPerRev = 16.0;
constexpr double kMaxTicksPerRev = 1e6;

constexpr std::string_view kBusKeys[] = {"port", "baud", "timeout_ms", "device_watchdog_ms",
                                         "health"};
constexpr std::string_view kActuatorKeys[] = {"id", "ticks_per_rev", "ticks_per_rad", "zero_ticks",
                                              "direction"};

int parse_direction(const YamlNode& node) {
  if (node.is_scalar()) {
    const std::string& s = node.raw().Scalar();
    if (s == "1" || s == "+1") return 1;
    if (s == "-1") return -1;
  }
  node.fail("expected 1 or -1 (-1 for a mirrored servo), found " + node.describe());
}

class Feetech final : public Protocol {
 public:
  Feetech(std::string_view name, ft::Series series) : name_(name), series_(series) {}

  std::string_view name() const override { return name_; }
  std::string device_guard_note(const BusConfig&) const override {
    return "no device-side guard (Feetech STS/SCS servos have no bus watchdog): if the host "
           "dies, the servos hold their last goal with torque on";
  }
  std::span<const std::string_view> bus_keys() const override { return kBusKeys; }
  std::span<const std::string_view> actuator_keys() const override { return kActuatorKeys; }

  void read_bus(const YamlNode& node, BusConfig& bus) const override {
    refuse_device_watchdog(node, "Feetech STS/SCS servos have no device-side watchdog");
    const YamlNode port = node.at("port");
    bus.port = port.as_string();
    if (bus.port.empty()) port.fail("expected a device path such as /dev/ttyUSB0, found \"\"");
    if (auto n = node.find("baud")) {
      const std::int64_t baud = n->as_int();
      bool known = false;
      for (int b : kBauds) known = known || b == baud;
      if (!known) {
        n->fail(
            "expected a Feetech baud rate (1000000, 500000, 250000, 128000, 115200, 76800, "
            "57600 or 38400), found " +
            n->describe());
      }
      bus.baud = static_cast<int>(baud);
    }
    if (auto n = node.find("timeout_ms")) {
      const double ms = n->as_double();
      if (!(ms > 0.0 && ms < 1000.0)) {
        n->fail("expected a number greater than 0 and less than 1000, found " + n->describe());
      }
      bus.timeout_s = ms / 1000.0;
    }
    ft::BusOptions options;
    if (auto n = node.find("health")) options.health = n->as_bool();
    bus.options = options;
  }

  void read_actuator(const YamlNode& node, const JointSpec& joint, const YamlNode& limits_node,
                     const BusConfig& bus, ActuatorBinding& out) const override {
    const YamlNode id_node = node.at("id");
    const std::int64_t id = id_node.as_int();
    if (id < 0 || id > ft::kMaxDeviceId) {
      id_node.fail("expected a servo id from 0 to " + std::to_string(ft::kMaxDeviceId) + " for " +
                   std::string(name_) + ", found " + id_node.describe());
    }
    out.device_id = static_cast<int>(id);
    for (const auto& other : bus.actuators) {
      if (other.device_id == id) {
        id_node.fail("servo id " + std::to_string(id) + " is already used by joint " + other.joint +
                     " on bus " + bus.name);
      }
    }
    const bool sts = series_ == ft::Series::sts;
    const double native_per_rev = sts ? ft::kStsStepsPerRev : ft::kScsStepsPerRev;
    const auto per_rev = node.find("ticks_per_rev");
    const auto per_rad = node.find("ticks_per_rad");
    if (per_rev && per_rad) per_rad->fail("give either ticks_per_rev or ticks_per_rad, not both");
    std::string scale;
    if (per_rad) {
      out.ticks_per_rad =
          per_rad->as_double_in(kMinTicksPerRev / (2.0 * kPi), kMaxTicksPerRev / (2.0 * kPi));
      scale = format_number(out.ticks_per_rad) + " ticks/rad";
    } else {
      const double ticks_per_rev =
          per_rev ? per_rev->as_double_in(kMinTicksPerRev, kMaxTicksPerRev) : native_per_rev;
      out.ticks_per_rad = ticks_per_rev / (2.0 * kPi);
      scale = format_number(ticks_per_rev) + " ticks/rev";
    }
    // The middle of the range by default: 2048 (STS), 512 (SCS).
    out.zero_ticks = sts ? 2048 : 512;
    if (auto n = node.find("zero_ticks")) {
      out.zero_ticks = static_cast<std::int32_t>(n->as_int_in(0, max_ticks()));
    }
    if (auto n = node.find("direction")) out.direction = parse_direction(*n);
    check_ticks(limits_node.at("min_deg"), joint.limits.min_position, out, scale);
    check_ticks(limits_node.at("max_deg"), joint.limits.max_position, out, scale);
  }

  // Sync Write of 2-byte goals (8 + 3 N bytes) each cycle; STS reads with one
  // Sync Read (8 + N) and N status packets of 8 bytes, SCS with N Reads of 8
  // bytes answered by 8 bytes each. 10 bits per byte (start, 8 data, stop).
  double wire_bits_per_cycle(const BusConfig& bus) const override {
    const double n = static_cast<double>(bus.actuators.size());
    const double write = 8.0 + 3.0 * n;
    const double read = series_ == ft::Series::sts ? (8.0 + n) + 8.0 * n : 16.0 * n;
    return 10.0 * (write + read);
  }
  double read_wire_bits_per_cycle(const BusConfig& bus) const override {
    const double n = static_cast<double>(bus.actuators.size());
    return 10.0 * (series_ == ft::Series::sts ? (8.0 + n) + 8.0 * n : 16.0 * n);
  }
  int read_transactions_per_cycle(const BusConfig& bus) const override {
    return series_ == ft::Series::sts ? 1 : static_cast<int>(bus.actuators.size());
  }

  std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) const override {
    return std::make_unique<FeetechBus>(config, series_, open_bus_serial(config));
  }

 private:
  std::int32_t max_ticks() const {
    return series_ == ft::Series::sts ? ft::kStsMaxPosition : ft::kScsMaxPosition;
  }

  // A limit must be a position the servo takes in position mode; the mapping
  // is the one ActuatorBinding::to_ticks applies at run time.
  void check_ticks(const YamlNode& limit_node, double rad, const ActuatorBinding& b,
                   const std::string& scale) const {
    const double ticks = std::round(b.zero_ticks + b.direction * rad * b.ticks_per_rad);
    if (ticks < 0.0 || ticks > static_cast<double>(max_ticks())) {
      std::ostringstream tick_text;
      tick_text.precision(12);
      tick_text << ticks;
      limit_node.fail(format_number(rad_to_deg(rad)) + " deg maps to step " + tick_text.str() +
                      " (zero_ticks " + std::to_string(b.zero_ticks) + ", direction " +
                      std::to_string(b.direction) + ", " + scale + "), outside the " +
                      std::string(name_) + " position range 0.." + std::to_string(max_ticks()));
    }
  }

  std::string_view name_;
  ft::Series series_;
};

}  // namespace

const Protocol& feetech_sts_protocol() {
  static const Feetech protocol("feetech_sts", ft::Series::sts);
  return protocol;
}

const Protocol& feetech_scs_protocol() {
  static const Feetech protocol("feetech_scs", ft::Series::scs);
  return protocol;
}

bool feetech_series(std::string_view protocol, ft::Series& series) {
  if (protocol == "feetech_sts") {
    series = ft::Series::sts;
    return true;
  }
  if (protocol == "feetech_scs") {
    series = ft::Series::scs;
    return true;
  }
  return false;
}

}  // namespace animrt
