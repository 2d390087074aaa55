#include "animrt/bridge/modbus/modbus_protocol.hpp"

#include <any>
#include <cmath>
#include <filesystem>
#include <string>

#include "animrt/bridge/device_watchdog.hpp"
#include "animrt/bridge/modbus/modbus_bus.hpp"

namespace animrt {
namespace {

constexpr std::string_view kTcpKeys[] = {"port", "timeout_ms", "reconnect_ms", "device_watchdog_ms",
                                         "health"};
constexpr std::string_view kRtuKeys[] = {
    "port", "baud", "parity", "stop_bits", "timeout_ms", "device_watchdog_ms", "health"};
constexpr std::string_view kActuatorKeys[] = {"slave", "map", "m_per_rad", "zero_m"};

// The longest communication timeout set from the robot file: a guard of a
// minute protects nothing a figure needs.
constexpr double kMaxGuardMs = 60000.0;

void read_timeout(const YamlNode& node, BusConfig& bus) {
  bus.timeout_s = 0.02;
  if (auto n = node.find("timeout_ms")) {
    const double ms = n->as_double();
    if (!(ms > 0.0 && ms < 10000.0)) {
      n->fail("expected a number greater than 0 and less than 10000, found " + n->describe());
    }
    bus.timeout_s = ms / 1000.0;
  }
}

ModbusBusOptions::Health read_health(const YamlNode& node) {
  using Health = ModbusBusOptions::Health;
  const auto n = node.find("health");
  if (!n) return Health::off;
  const std::string v = n->is_scalar() ? n->as_string() : "";
  if (v == "off") return Health::off;
  if (v == "packed") return Health::packed;
  if (v == "round_robin") return Health::round_robin;
  n->fail("expected off, packed or round_robin, found " + n->describe());
}

// The joint's register map, resolved against the robot file's folder.
std::shared_ptr<const modbus::RegisterMap> load_joint_map(const YamlNode& node,
                                                          const YamlNode& map_node,
                                                          const std::string& given) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(node.file()).parent_path();
  const fs::path resolved = fs::path(given).is_absolute() ? fs::path(given) : folder / given;
  if (!fs::is_regular_file(resolved)) {
    map_node.fail("register map not found: " + quote_path(given) + " (resolved to " +
                  quote_path(resolved.string()) + ")");
  }
  return modbus::load_register_map(resolved.string());
}

// The device-side watchdog in the map's counts, or a refusal when the bus
// asks for one the map cannot set.
void set_watchdog_counts(const YamlNode& map_node, const std::string& given, const JointSpec& joint,
                         const BusConfig& bus, ModbusJointOptions& j) {
  const modbus::RegisterMap& m = *j.map;
  const auto& bus_options = std::any_cast<const ModbusBusOptions&>(bus.options);
  if (bus_options.device_watchdog_ms > 0.0 && m.watchdog.configured) {
    const double counts = std::ceil(bus_options.device_watchdog_ms / m.watchdog.unit_ms - 1e-9);
    if (counts > 65535.0) {
      map_node.fail("device_watchdog_ms " + format_number(bus_options.device_watchdog_ms) +
                    " is more than the watchdog register of " + quote_path(given) +
                    " holds (65535 counts of " + format_number(m.watchdog.unit_ms) + " ms)");
    }
    j.watchdog_counts = static_cast<std::uint16_t>(std::max(1.0, counts));
  } else if (bus_options.device_watchdog_given && bus_options.device_watchdog_ms > 0.0) {
    throw InputError(bus_options.device_watchdog_where, bus_options.device_watchdog_path,
                     "the register map " + quote_path(given) + " of joint " + joint.name +
                         " names no watchdog or timeout register, so animrt cannot set a "
                         "device-side watchdog on this bus: remove " +
                         std::string(kDeviceWatchdogKey) +
                         " or name the drive's timeout register (watchdog) in the map");
  }
}

// How the joint maps to the actuator's stroke (m_per_rad, zero_m).
void read_stroke(const YamlNode& node, const YamlNode& map_node, const std::string& given,
                 const JointSpec& joint, ModbusJointOptions& j) {
  const modbus::RegisterMap& m = *j.map;
  const auto per = node.find("m_per_rad");
  const auto zero = node.find("zero_m");
  const bool prismatic = joint.type == JointType::prismatic;
  if (prismatic) {
    // The joint is the actuator's stroke itself: metres in, metres out.
    if (m.unit != "m") {
      map_node.fail("joint " + joint.name + " is prismatic (metres) but the map " + given +
                    " is in radians; use a map in metres");
    }
    if (per) {
      per->fail("joint " + joint.name +
                " is prismatic: the actuator moves it directly, so there is no stroke per "
                "radian (zero_m alone sets the actuator position at joint 0 m)");
    }
    j.per_rad = 1.0;
    if (zero) j.zero = zero->as_double_in(-1000.0, 1000.0);
  } else if (m.unit == "m") {
    if (!per) {
      node.fail("missing key m_per_rad: the map " + given +
                " is in metres, so the joint needs the stroke per radian (negative to reverse)");
    }
    j.per_rad = per->as_double();
    if (!(std::abs(j.per_rad) >= 1e-6 && std::abs(j.per_rad) <= 10.0))
      per->fail("expected a magnitude from 1e-06 to 10 m/rad (negative to reverse), found " +
                per->describe());
    if (zero) j.zero = zero->as_double_in(-1000.0, 1000.0);
  } else if (per || zero) {
    (per ? *per : *zero)
        .fail("the map " + given + " is in radians; m_per_rad and zero_m apply to maps in metres");
  }
}

// Two joints of one slave must not share a register.
void check_shared_registers(const YamlNode& slave, const JointSpec& joint, const BusConfig& bus,
                            const ModbusJointOptions& j) {
  const modbus::RegisterMap& m = *j.map;
  for (const auto& other : bus.actuators) {
    const auto& o = std::any_cast<const ModbusJointOptions&>(other.options);
    if (o.slave != j.slave) continue;
    for (const auto& a : m.spans()) {
      for (const auto& b : o.map->spans()) {
        if (a.first == b.first && a.second.first < b.second.second &&
            b.second.first < a.second.second) {
          slave.fail("registers overlap: joint " + joint.name + " and joint " + other.joint +
                     " on slave " + std::to_string(j.slave) + " both use " +
                     modbus::to_string(a.first) + " register " +
                     std::to_string(std::max(a.second.first, b.second.first)));
        }
      }
    }
  }
}

// The joint's limits fit in the range the map gives the actuator.
void check_range(const YamlNode& limits_node, const std::string& given, const JointSpec& joint,
                 const ModbusJointOptions& j) {
  const modbus::RegisterMap& m = *j.map;
  if (!m.has_range) return;
  const bool prismatic = joint.type == JointType::prismatic;
  static constexpr const char* kDegKeys[] = {"min_deg", "max_deg"};
  static constexpr const char* kMetreKeys[] = {"min_m", "max_m"};
  for (const char* key : prismatic ? kMetreKeys : kDegKeys) {
    const double rad = key[1] == 'i' ? joint.limits.min_position : joint.limits.max_position;
    const double si = j.zero + j.per_rad * rad;
    if (si < m.range_min - 1e-12 || si > m.range_max + 1e-12) {
      limits_node.at(key).fail(
          (prismatic ? format_number(rad) + " m" : format_number(rad_to_deg(rad)) + " deg") +
          " maps to " + format_number(si) + " " + m.unit + ", outside the range of " + given +
          " (" + format_number(m.range_min) + ".." + format_number(m.range_max) + " " + m.unit +
          ")");
    }
  }
}

class ModbusProtocol final : public Protocol {
 public:
  explicit ModbusProtocol(bool tcp) : tcp_(tcp) {}
  std::string_view name() const override { return tcp_ ? "modbus-tcp" : "modbus-rtu"; }
  bool drives_prismatic() const override { return true; }
  std::span<const std::string_view> bus_keys() const override {
    return tcp_ ? std::span<const std::string_view>(kTcpKeys)
                : std::span<const std::string_view>(kRtuKeys);
  }
  std::span<const std::string_view> actuator_keys() const override { return kActuatorKeys; }
  std::string device_guard_note(const BusConfig& bus) const override {
    const auto* options = std::any_cast<ModbusBusOptions>(&bus.options);
    if (options != nullptr && options->device_watchdog_ms == 0.0) {
      return "no device-side guard (device_watchdog_ms: off): if the host dies, the drives hold "
             "their last target";
    }
    std::string unguarded;
    std::size_t count = 0;
    for (const ActuatorBinding& b : bus.actuators) {
      const auto* j = std::any_cast<ModbusJointOptions>(&b.options);
      if (j != nullptr && j->map && j->map->watchdog.configured) continue;
      unguarded += (unguarded.empty() ? "" : ", ") + b.joint;
      ++count;
    }
    if (count == 0) return {};
    if (count == bus.actuators.size()) {
      return "no device-side guard (a register map names no watchdog register; set the drive's "
             "own communication timeout with its vendor tool): if the host dies, the drives hold "
             "their last target";
    }
    return "no device-side guard for " + unguarded +
           " (their register maps name no watchdog register; set the drive's own communication "
           "timeout with its vendor tool): if the host dies, those drives hold their last target";
  }

  void read_bus(const YamlNode& node, BusConfig& bus) const override {
    const YamlNode port = node.at("port");
    bus.port = port.as_string();
    ModbusBusOptions options;
    options.device_watchdog_ms = read_device_watchdog_ms(node, bus.loop_period_s, 1.0, kMaxGuardMs,
                                                         "the drives' communication timeout");
    if (const auto given = node.find(kDeviceWatchdogKey)) {
      options.device_watchdog_given = true;
      options.device_watchdog_where = given->location();
      options.device_watchdog_path = given->path();
    }
    options.tcp = tcp_;
    options.health = read_health(node);
    if (tcp_) {
      const auto colon = bus.port.rfind(':');
      bool ok = colon != std::string::npos && colon > 0 && colon + 1 < bus.port.size();
      if (ok) {
        const std::string p = bus.port.substr(colon + 1);
        ok = p.find_first_not_of("0123456789") == std::string::npos && p.size() <= 5 &&
             std::stoi(p) >= 1 && std::stoi(p) <= 65535;
      }
      if (!ok) port.fail("expected HOST:PORT (e.g. 192.168.1.20:502), found " + port.describe());
      if (auto n = node.find("reconnect_ms"))
        options.reconnect_min_s = n->as_double_in(1, 60000) / 1000.0;
      options.reconnect_max_s = std::max(options.reconnect_max_s, options.reconnect_min_s);
    } else {
      if (bus.port.empty()) port.fail("expected a device path such as /dev/ttyUSB0, found \"\"");
      bus.baud = 19200;
      if (auto n = node.find("baud")) bus.baud = static_cast<int>(n->as_int_in(300, 4'000'000));
      if (auto n = node.find("parity")) {
        const std::string p = n->as_string();
        if (p == "none") {
          options.parity = 'N';
        } else if (p == "even") {
          options.parity = 'E';
        } else if (p == "odd") {
          options.parity = 'O';
        } else {
          n->fail("expected none, even or odd, found " + n->describe());
        }
      } else {
        options.parity = 'E';  // the Modbus serial line default
      }
      if (auto n = node.find("stop_bits")) options.stop_bits = static_cast<int>(n->as_int_in(1, 2));
    }
    read_timeout(node, bus);
    bus.options = options;
  }

  void read_actuator(const YamlNode& node, const JointSpec& joint, const YamlNode& limits_node,
                     const BusConfig& bus, ActuatorBinding& out) const override {
    ModbusJointOptions j;
    const YamlNode slave = node.at("slave");
    j.slave = static_cast<int>(slave.as_int());
    if (j.slave < 1 || j.slave > 247) {
      slave.fail("expected a slave id from 1 to 247, found " + slave.describe());
    }
    const YamlNode map_node = node.at("map");
    const std::string given = map_node.as_string();
    j.map = load_joint_map(node, map_node, given);
    set_watchdog_counts(map_node, given, joint, bus, j);
    const auto& bus_options = std::any_cast<const ModbusBusOptions&>(bus.options);
    if (bus_options.health != ModbusBusOptions::Health::off && !j.map->health.any()) {
      map_node.fail("bus " + bus.name + " reads health, but the register map " + quote_path(given) +
                    " names no health registers (a health section with current, temperature, "
                    "voltage or fault_code)");
    }
    read_stroke(node, map_node, given, joint, j);
    check_shared_registers(slave, joint, bus, j);
    check_range(limits_node, given, joint, j);
    out.device_id = j.slave;
    out.options = j;
  }

  // RTU: per actuator a two-register write and read with their answers
  // (38 characters) and the 3.5-character silence after each of the four
  // frames, at 11 bits per character. TCP: not estimated.
  double wire_bits_per_cycle(const BusConfig& bus) const override {
    if (tcp_) return 0.0;
    return 11.0 * (38.0 + 4 * 3.5) * static_cast<double>(bus.actuators.size());
  }

  std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) const override {
    return std::make_unique<ModbusBus>(config);
  }

 private:
  bool tcp_;
};

}  // namespace

const Protocol& modbus_tcp_protocol() {
  static const ModbusProtocol protocol(true);
  return protocol;
}

const Protocol& modbus_rtu_protocol() {
  static const ModbusProtocol protocol(false);
  return protocol;
}

}  // namespace animrt
