#include "animrt/runtime/robot_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "animrt/bridge/protocol.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "file_kind.hpp"
#include "imu_section.hpp"

namespace animrt {
namespace {

std::string num(double value) { return format_number(value); }
std::string found(const YamlNode& node) { return node.describe(); }

// Position of `key` itself inside `map` (the line a user reads as "declared
// here"), falling back to the map's position.
Location key_location(const YamlNode& map, std::string_view key) {
  for (auto it = map.raw().begin(); it != map.raw().end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key && !it->first.Mark().is_null()) {
      return Location{map.file(), it->first.Mark().line + 1, it->first.Mark().column + 1};
    }
  }
  return map.location();
}

std::string key_path(const YamlNode& parent, std::string_view key) {
  return parent.path().empty() ? std::string(key) : parent.path() + "." + std::string(key);
}

// Plausible ranges of the robot file's numbers (docs/config.md lists them).
constexpr double kMaxWatchdogS = 5.0;
constexpr double kMaxStartRampMaxS = 120.0;
constexpr double kMaxStopDeadlineS = 30.0;
constexpr double kMaxFollowingWindowS = 5.0;
// Every layer is sampled every cycle; a figure has a few parts that move on
// their own (a neck, a jaw, eyes), so more than 16 is a mistake that costs
// cycle time.
constexpr std::size_t kMaxMotionLayers = 16;

std::string seconds(double s) { return format_number(s) + " s"; }

// The watchdog and the following-error window count in cycles: shorter
// than two periods, one late answer would already fault a healthy device.
void check_two_periods(const YamlNode& n, double value, double rate_hz) {
  if (value < 2.0 / rate_hz) {
    std::ostringstream msg;
    msg << "expected at least two loop periods (" << 2.0 / rate_hz << " s at loop.rate_hz "
        << rate_hz << "), found \"" << n.as_string() << "\"";
    n.fail(msg.str());
  }
}

// Device health limits: safety.health, or a bus's health_limits. A warning
// must come before its fault.
HealthLimits parse_health_limits(const YamlNode& node, double rate_hz,
                                 const HealthLimits& base = {}) {
  node.allow_only({"temperature_warn_c", "temperature_fault_c", "voltage_warn_v", "voltage_fault_v",
                   "stall_current_a", "stall_time_s", "stall_error_deg", "error_bits"});
  HealthLimits h = base;  // a device's own limits: the keys given over its bus's
  const auto t_warn = node.find("temperature_warn_c");
  const auto t_fault = node.find("temperature_fault_c");
  if (t_warn) h.temperature_warn_c = t_warn->as_double_in(0.0, 200.0);
  if (t_fault) h.temperature_fault_c = t_fault->as_double_in(0.0, 200.0);
  if (h.temperature_fault_c <= h.temperature_warn_c) {
    if (t_fault) {
      t_fault->fail("expected more than temperature_warn_c (" +
                    format_number(h.temperature_warn_c) + "), found " + t_fault->describe());
    }
    t_warn->fail("expected less than temperature_fault_c (" + format_number(h.temperature_fault_c) +
                 "), found " + t_warn->describe());
  }
  const auto v_warn = node.find("voltage_warn_v");
  const auto v_fault = node.find("voltage_fault_v");
  if (v_warn) h.voltage_warn_v = v_warn->as_double_in(0.0, 100.0);
  if (v_fault) h.voltage_fault_v = v_fault->as_double_in(0.0, 100.0);
  if (h.voltage_fault_v >= h.voltage_warn_v) {
    if (v_fault) {
      v_fault->fail("expected less than voltage_warn_v (" + format_number(h.voltage_warn_v) +
                    "), found " + v_fault->describe());
    }
    v_warn->fail("expected more than voltage_fault_v (" + format_number(h.voltage_fault_v) +
                 "), found " + v_warn->describe());
  }
  if (auto n = node.find("stall_current_a")) h.stall_current_a = n->as_double_in(0.001, 1000.0);
  if (auto n = node.find("stall_time_s")) {
    h.stall_time_s = n->as_double_in(0.0, 60.0);
    check_two_periods(*n, h.stall_time_s, rate_hz);
  }
  if (auto n = node.find("stall_error_deg"))
    h.stall_error_rad = deg_to_rad(n->as_double_in(0.0, 180.0));
  if (auto n = node.find("error_bits")) {
    const std::string v = n->is_scalar() ? n->raw().Scalar() : "";
    if (v == "fault") {
      h.error_bits = HealthLimits::Bits::fault;
    } else if (v == "warn") {
      h.error_bits = HealthLimits::Bits::warn;
    } else if (v == "ignore") {
      h.error_bits = HealthLimits::Bits::ignore;
    } else {
      n->fail("expected fault, warn or ignore, found " + n->describe());
    }
  }
  return h;
}

SafetyConfig parse_safety(const YamlNode& node, double rate_hz) {
  node.allow_only({"watchdog_timeout_s", "start_ramp_s", "stop_ramp_s", "start_ramp_max_s",
                   "stop_deadline_s", "following_error_deg", "following_error_mm",
                   "following_error_window_s", "health", "tilt_limit_deg", "tilt_time_s", "on_tilt",
                   "tilt_hold_s"});
  SafetyConfig safety;
  if (auto n = node.find("health")) safety.health = parse_health_limits(*n, rate_hz);
  parse_tilt_watch(node, safety);
  if (auto n = node.find("watchdog_timeout_s")) {
    safety.watchdog_timeout_s = n->as_positive_double();
    if (safety.watchdog_timeout_s > kMaxWatchdogS) {
      n->fail("expected at most " + seconds(kMaxWatchdogS) + ", found " + n->describe());
    }
    check_two_periods(*n, safety.watchdog_timeout_s, rate_hz);
  }
  if (auto n = node.find("start_ramp_s")) safety.start_ramp_s = n->as_double_in(0.0, 60.0);
  if (auto n = node.find("stop_ramp_s")) safety.stop_ramp_s = n->as_double_in(0.0, 60.0);
  if (auto n = node.find("start_ramp_max_s")) {
    safety.start_ramp_max_s = n->as_double_in(0.0, kMaxStartRampMaxS);
    if (!(safety.start_ramp_max_s > safety.start_ramp_s)) {
      n->fail("expected more than start_ramp_s (" + seconds(safety.start_ramp_s) + "), found " +
              n->describe());
    }
  } else if (!(safety.start_ramp_max_s > safety.start_ramp_s)) {
    node.at("start_ramp_s")
        .fail("expected less than start_ramp_max_s (" + seconds(safety.start_ramp_max_s) +
              " by default); set start_ramp_max_s too");
  }
  if (auto n = node.find("stop_deadline_s")) {
    safety.stop_deadline_s = n->as_double_in(0.0, kMaxStopDeadlineS);
    if (safety.stop_deadline_s < safety.stop_ramp_s) {
      n->fail("expected at least stop_ramp_s (" + seconds(safety.stop_ramp_s) + "), found " +
              n->describe());
    }
  } else if (safety.stop_deadline_s < safety.stop_ramp_s) {
    node.at("stop_ramp_s")
        .fail("expected at most stop_deadline_s (" + seconds(safety.stop_deadline_s) +
              " by default); set stop_deadline_s too");
  }
  if (auto n = node.find("following_error_deg"))
    safety.following_error_rad = deg_to_rad(n->as_double_in(0.5, 180.0));
  if (auto n = node.find("following_error_mm"))
    safety.following_error_m = n->as_double_in(0.1, 1000.0) / 1000.0;
  if (auto n = node.find("following_error_window_s")) {
    safety.following_error_window_s = n->as_double_in(0.0, kMaxFollowingWindowS);
    check_two_periods(*n, safety.following_error_window_s, rate_hz);
  } else if (safety.following_error_window_s < 2.0 / rate_hz) {
    node.fail("the default following_error_window_s (" + seconds(safety.following_error_window_s) +
              ") is shorter than two loop periods; set following_error_window_s");
  }
  return safety;
}

// sim.health: the simulated servos' thermal, supply and current model.
void parse_sim_health(const YamlNode& node, SimHealthSettings& h) {
  node.allow_only({"ambient_c", "thermal_tau_s", "heat_c_per_a2", "supply_v", "supply_ohm",
                   "idle_current_a", "current_per_rad_s", "stall_current_a", "overload_s",
                   "trip_c"});
  if (auto n = node.find("ambient_c")) h.ambient_c = n->as_double_in(-40.0, 150.0);
  if (auto n = node.find("thermal_tau_s")) h.thermal_tau_s = n->as_double_in(0.001, 1e5);
  if (auto n = node.find("heat_c_per_a2")) h.heat_c_per_a2 = n->as_double_in(0.0, 1000.0);
  if (auto n = node.find("supply_v")) h.supply_v = n->as_double_in(0.0, 100.0);
  if (auto n = node.find("supply_ohm")) h.supply_ohm = n->as_double_in(0.0, 100.0);
  if (auto n = node.find("idle_current_a")) h.idle_current_a = n->as_double_in(0.0, 100.0);
  if (auto n = node.find("current_per_rad_s")) h.current_per_rad_s = n->as_double_in(0.0, 100.0);
  if (auto n = node.find("stall_current_a")) h.stall_current_a = n->as_double_in(0.0, 100.0);
  if (auto n = node.find("overload_s")) h.overload_s = n->as_double_in(0.0, 3600.0);
  if (auto n = node.find("trip_c")) h.trip_c = n->as_double_in(0.0, 250.0);
}

// sim.inject: health changes at a time, one key saying what.
SimHealthInjection parse_injection(const YamlNode& node) {
  node.allow_only({"id", "at_s", "temperature_c", "blocked", "supply_v", "hardware_error"});
  SimHealthInjection i;
  i.device_id = static_cast<int>(node.at("id").as_int_in(0, 65535));
  i.at_s = node.at("at_s").as_double_in(0.0, 1e6);
  int kinds = 0;
  using Kind = SimHealthInjection::Kind;
  if (auto n = node.find("temperature_c")) {
    i.kind = Kind::temperature;
    i.value = n->as_double_in(-40.0, 250.0);
    ++kinds;
  }
  if (auto n = node.find("blocked")) {
    i.kind = Kind::blocked;
    i.value = n->as_bool() ? 1.0 : 0.0;
    ++kinds;
  }
  if (auto n = node.find("supply_v")) {
    i.kind = Kind::supply;
    i.value = n->as_double_in(0.0, 100.0);
    ++kinds;
  }
  if (auto n = node.find("hardware_error")) {
    i.kind = Kind::hardware_error;
    i.value = static_cast<double>(n->as_int_in(0, 255));
    ++kinds;
  }
  if (kinds != 1) {
    node.fail("expected exactly one of temperature_c, blocked, supply_v, hardware_error, found " +
              std::to_string(kinds));
  }
  return i;
}

// sim.switches: a simulated CiA 402 drive's home and limit switches.
SimDriveSwitches parse_switches(const YamlNode& node) {
  node.allow_only(
      {"id", "home_from_deg", "home_to_deg", "negative_limit_deg", "positive_limit_deg"});
  SimDriveSwitches s;
  s.device_id = static_cast<int>(node.at("id").as_int_in(1, 127));
  constexpr double kTravel = 1e6;
  if (auto n = node.find("home_from_deg")) s.home_from_deg = n->as_double_in(-kTravel, kTravel);
  if (auto n = node.find("home_to_deg")) {
    s.home_to_deg = n->as_double_in(-kTravel, kTravel);
    if (!(s.home_to_deg > s.home_from_deg))
      n->fail("expected more than home_from_deg, found " + n->describe());
  }
  s.has_home = node.find("home_from_deg") || node.find("home_to_deg");
  if (auto n = node.find("negative_limit_deg")) {
    s.negative_limit_deg = n->as_double_in(-kTravel, kTravel);
  }
  if (auto n = node.find("positive_limit_deg")) {
    s.positive_limit_deg = n->as_double_in(-kTravel, kTravel);
    if (!(s.positive_limit_deg > s.negative_limit_deg))
      n->fail("expected more than negative_limit_deg, found " + n->describe());
  }
  return s;
}

SimBusSettings parse_sim(const YamlNode& node) {
  node.allow_only({"time_constant_s", "max_speed_dps", "wire_time", "return_delay_us",
                   "firmware_version", "health", "inject", "switches"});
  SimBusSettings sim;
  if (auto n = node.find("switches")) {
    if (!n->is_sequence()) n->fail("expected a list of drives' switches, found " + n->describe());
    for (const YamlNode& item : n->items()) sim.switches.push_back(parse_switches(item));
  }
  if (auto n = node.find("health")) parse_sim_health(*n, sim.health);
  if (auto n = node.find("inject")) {
    if (!n->is_sequence()) n->fail("expected a list of injections, found " + n->describe());
    for (const YamlNode& item : n->items()) sim.health.inject.push_back(parse_injection(item));
  }
  if (auto n = node.find("time_constant_s")) sim.time_constant_s = n->as_double_in(1e-4, 10.0);
  if (auto n = node.find("max_speed_dps")) {
    sim.max_speed_rad_s = deg_to_rad(n->as_double_in(0.01, 100000.0));
  }
  if (auto n = node.find("wire_time")) sim.wire_time = n->as_bool();
  // Dynamixel's Return Delay Time register counts 2 us units, 0..254.
  if (auto n = node.find("return_delay_us")) {
    sim.return_delay_us = static_cast<int>(n->as_int_in(0, 508));
  }
  // The firmware version simulated Dynamixel servos report (Fast Sync Read
  // needs 45 or later).
  if (auto n = node.find("firmware_version")) {
    sim.firmware_version = static_cast<int>(n->as_int_in(1, 255));
  }
  return sim;
}

BusConfig parse_bus(const std::string& name, const YamlNode& node, const YamlNode& buses,
                    double rate_hz) {
  BusConfig bus;
  bus.name = name;
  bus.loop_period_s = 1.0 / rate_hz;
  bus.where = key_location(buses, name);

  const YamlNode protocol_node = node.at("protocol");
  bus.protocol = protocol_node.as_string();
  const Protocol* protocol = find_protocol(bus.protocol);
  if (!protocol) {
    protocol_node.fail("unknown protocol " + found(protocol_node) +
                       " (supported: " + supported_protocols() + ")");
  }
  std::vector<std::string_view> keys{"protocol"};
  for (auto key : protocol->bus_keys()) keys.push_back(key);
  keys.push_back("sim");
  keys.push_back("health_limits");
  node.allow_only(keys);

  protocol->read_bus(node, bus);
  if (auto n = node.find("sim")) {
    bus.sim = parse_sim(*n);
    if (!bus.sim.switches.empty() && bus.protocol != "cia402") {
      n->at("switches").fail("switches are simulated on cia402 drives only (for their homing)");
    }
  }
  if (auto n = node.find("health_limits")) bus.health_limits = parse_health_limits(*n, rate_hz);
  return bus;
}

// sim.switches or sim.inject of a device the bus does not have would
// simulate nothing (an injected fault that never comes: a test of nothing):
// the id is almost always a typo. After the joints, which bind the devices.
void check_sim_ids(const YamlNode& buses, const RobotConfig& config) {
  for (const BusConfig& bus : config.buses) {
    const auto sim = buses.at(bus.name).find("sim");
    if (!sim) continue;
    std::string ids;
    for (const ActuatorBinding& a : bus.actuators) {
      ids += (ids.empty() ? "" : ", ") + std::to_string(a.device_id);
    }
    for (const char* key : {"switches", "inject"}) {
      const auto list = sim->find(key);
      if (!list) continue;
      for (const YamlNode& item : list->items()) {
        const YamlNode id = item.at("id");
        const auto n = id.as_int();
        const bool bound = std::any_of(bus.actuators.begin(), bus.actuators.end(),
                                       [&](const ActuatorBinding& a) { return a.device_id == n; });
        if (!bound) {
          id.fail("no device on bus " + bus.name + " has id " + std::to_string(n) +
                  " (its devices: " + ids + ")");
        }
      }
    }
  }
}

std::vector<BusConfig> parse_buses(const YamlNode& node, double rate_hz) {
  const auto entries = node.entries();
  if (entries.empty()) node.fail("expected at least one bus, found an empty map");
  std::vector<BusConfig> buses;
  for (const auto& [name, value] : entries) {
    BusConfig bus = parse_bus(name, value, node, rate_hz);
    // Two buses on one port would fight over the line.
    for (const auto& other : buses) {
      if (other.port == bus.port && !(find_protocol(other.protocol)->shares_port() &&
                                      find_protocol(bus.protocol)->shares_port())) {
        value.at("port").fail("port " + quote_path(bus.port) + " is already used by bus " +
                              other.name);
      }
    }
    buses.push_back(std::move(bus));
  }
  return buses;
}

// The keys of a joint's limits and home in its unit: degrees for a revolute
// joint, metres for a prismatic one.
struct UnitKeys {
  const char *min, *max, *velocity, *acceleration, *home;
  double to_si;
};
UnitKeys unit_keys(JointType type) {
  if (type == JointType::prismatic)
    return {"min_m", "max_m", "velocity_mps", "acceleration_mps2", "home_m", 1.0};
  return {"min_deg", "max_deg", "velocity_dps", "acceleration_dps2", "home_deg", deg_to_rad(1.0)};
}

// Plausible limits in the file's unit: positions within +-position.
struct UnitRanges {
  double position, velocity_lo, velocity_hi, acceleration_lo, acceleration_hi;
};
UnitRanges unit_ranges(JointType type) {
  if (type == JointType::prismatic) return {10.0, 1e-5, 10.0, 1e-5, 1000.0};
  return {3600.0, 0.01, 5000.0, 0.01, 1e6};
}

JointType parse_joint_type(const YamlNode& joint) {
  const auto node = joint.find("type");
  if (!node) return JointType::revolute;
  const std::string type = node->as_string();
  if (type == "revolute") return JointType::revolute;
  if (type == "prismatic") return JointType::prismatic;
  node->fail("expected revolute or prismatic, found " + found(*node));
}

JointLimits parse_limits(const YamlNode& node, JointType type) {
  const UnitKeys k = unit_keys(type);
  const UnitRanges r = unit_ranges(type);
  node.allow_only({k.min, k.max, k.velocity, k.acceleration});
  const double min_v = node.at(k.min).as_double_in(-r.position, r.position);
  const YamlNode max_node = node.at(k.max);
  const double max_v = max_node.as_double_in(-r.position, r.position);
  if (!(max_v > min_v)) {
    max_node.fail("expected a value greater than " + std::string(k.min) + " (" + num(min_v) +
                  "), found " + found(max_node));
  }
  JointLimits limits;
  limits.min_position = min_v * k.to_si;
  limits.max_position = max_v * k.to_si;
  limits.max_velocity = node.at(k.velocity).as_double_in(r.velocity_lo, r.velocity_hi) * k.to_si;
  limits.max_acceleration =
      node.at(k.acceleration).as_double_in(r.acceleration_lo, r.acceleration_hi) * k.to_si;
  return limits;
}

double parse_home(const YamlNode& joint, const YamlNode& limits_node, JointType type) {
  const UnitKeys k = unit_keys(type);
  const double min_v = limits_node.at(k.min).as_double();
  const double max_v = limits_node.at(k.max).as_double();
  const std::string range = num(min_v) + ".." + num(max_v);
  const std::string bounds = std::string(k.min) + ".." + k.max;
  const auto home = joint.find(k.home);
  if (!home) {
    if (min_v <= 0.0 && 0.0 <= max_v) return 0.0;
    throw InputError(joint.location(), key_path(joint, k.home),
                     "limits contradict the home pose: " + std::string(k.home) +
                         " defaults to 0, outside " + bounds + " (" + range + "); set " + k.home +
                         " inside the limits");
  }
  const double home_v = home->as_double();
  if (home_v < min_v || home_v > max_v) {
    home->fail("limits contradict the home pose: expected " + std::string(k.home) + " within " +
               bounds + " (" + range + "), found " + found(*home));
  }
  return home_v * k.to_si;
}

// Reads `actuator.bus` and hands the rest to the bus's protocol.
std::size_t parse_actuator(const YamlNode& node, const JointSpec& joint,
                           const YamlNode& limits_node, const std::vector<BusConfig>& buses,
                           ActuatorBinding& binding) {
  if (!node.is_map()) node.fail("expected a map, found " + found(node));
  const YamlNode bus_node = node.at("bus");
  const std::string bus_name = bus_node.as_string();
  std::size_t bus_index = buses.size();
  std::string defined;
  for (std::size_t i = 0; i < buses.size(); ++i) {
    defined += (defined.empty() ? "" : ", ") + buses[i].name;
    if (buses[i].name == bus_name) bus_index = i;
  }
  if (bus_index == buses.size()) {
    bus_node.fail("no bus named " + found(bus_node) + " (defined buses: " + defined + ")");
  }
  const BusConfig& bus = buses[bus_index];
  const Protocol& protocol = *find_protocol(bus.protocol);
  if (joint.type == JointType::prismatic && !protocol.drives_prismatic()) {
    bus_node.fail("joint " + joint.name + " is prismatic, and bus " + bus.name + " (" +
                  bus.protocol + ") drives revolute joints only");
  }
  std::vector<std::string_view> keys{"bus"};
  for (auto key : protocol.actuator_keys()) keys.push_back(key);
  keys.push_back("health_limits");
  node.allow_only(keys);
  protocol.read_actuator(node, joint, limits_node, bus, binding);
  return bus_index;
}

void parse_joints(const YamlNode& node, RobotConfig& config) {
  const auto entries = node.entries();
  if (entries.empty()) node.fail("expected at least one joint, found an empty map");
  for (const auto& [name, value] : entries) {
    JointSpec joint;
    joint.name = name;
    joint.type = parse_joint_type(value);
    value.allow_only({"type", "limits", unit_keys(joint.type).home, "actuator"});
    const YamlNode limits_node = value.at("limits");
    joint.limits = parse_limits(limits_node, joint.type);
    joint.home = parse_home(value, limits_node, joint.type);

    ActuatorBinding binding;
    binding.joint = name;
    binding.joint_index = static_cast<int>(config.joints.size());
    binding.min_position = joint.limits.min_position;
    binding.max_position = joint.limits.max_position;
    const YamlNode actuator = value.at("actuator");
    const std::size_t bus_index =
        parse_actuator(actuator, joint, limits_node, config.buses, binding);
    const BusConfig& bus = config.buses[bus_index];
    if (auto n = actuator.find("health_limits")) {
      binding.health_limits =
          parse_health_limits(*n, config.rate_hz, bus.health_limits.value_or(config.safety.health));
    }
    config.buses[bus_index].actuators.push_back(binding);
    config.joints.push_back(std::move(joint));
  }
}

// A bus that may take longer for one answer than the watchdog allows would
// fault its devices before it ever reported a timeout.
void check_bus_timeouts(const YamlNode& buses, const RobotConfig& config,
                        const std::optional<YamlNode>& safety) {
  const double watchdog = config.safety.watchdog_timeout_s;
  for (const BusConfig& bus : config.buses) {
    if (bus.timeout_s < watchdog) continue;
    const std::string limit = "the watchdog (safety.watchdog_timeout_s " + seconds(watchdog) +
                              (safety && safety->has("watchdog_timeout_s") ? "" : ", the default") +
                              ")";
    const YamlNode node = buses.at(bus.name);
    if (auto t = node.find("timeout_ms")) {
      t->fail("expected a bus timeout below " + limit + ", found " + t->describe() + " ms");
    }
    throw InputError(bus.where, key_path(buses, bus.name),
                     "the default bus timeout (" + seconds(bus.timeout_s) + ") is not below " +
                         limit + "; set timeout_ms");
  }
}

// The loop cannot run faster than the slowest bus carries one cycle's
// traffic. Buses sharing a port (CAN) add up.
void check_bus_load(const YamlNode& rate_node, const RobotConfig& config) {
  const double period = 1.0 / config.rate_hz;
  std::vector<bool> counted(config.buses.size(), false);
  for (std::size_t i = 0; i < config.buses.size(); ++i) {
    if (counted[i]) continue;
    double wire_s = 0.0;
    std::string names;
    for (std::size_t j = i; j < config.buses.size(); ++j) {
      const BusConfig& bus = config.buses[j];
      if (bus.port != config.buses[i].port) continue;
      counted[j] = true;
      const double bits = find_protocol(bus.protocol)->wire_bits_per_cycle(bus);
      if (bits <= 0.0) continue;  // not estimated (a network link)
      wire_s += bits / bus.baud;
      names += (names.empty() ? "" : " + ") + bus.name + " (" + bus.protocol + ", " +
               std::to_string(bus.actuators.size()) + " devices at " + std::to_string(bus.baud) +
               (bus.protocol == "mit" || bus.protocol == "cia402" ? " bit/s)" : " baud)");
    }
    if (wire_s > period) {
      std::ostringstream msg;
      msg.precision(3);
      msg << "bus " << names << " needs about " << wire_s * 1000.0
          << " ms of wire time per cycle, longer than the " << period * 1000.0
          << " ms loop period; expected at most " << std::floor(1.0 / wire_s) << " Hz, found "
          << rate_node.describe();
      rate_node.fail(msg.str());
    }
  }
}

// A file named by `node`, resolved against the robot file's folder; it must
// be a readable regular file.
std::string resolve_file(const YamlNode& node, const std::string& robot_path) {
  const std::string given = node.as_string();
  if (given.empty()) node.fail("expected a file path, found \"\"");
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(robot_path).parent_path();
  const std::string resolved =
      (fs::path(given).is_absolute() ? fs::path(given) : folder / given).string();
  const std::string problem = input_file_problem(resolved, kMaxMediaFileBytes);
  const std::string where =
      given == resolved ? quote_path(given)
                        : quote_path(given) + " (resolved against the robot file's folder to " +
                              quote_path(resolved) + ")";
  if (problem == kFileMissing) node.fail("file not found: " + where);
  if (!problem.empty()) node.fail(where + " " + problem);
  return resolved;
}

MotionConfig parse_motion(const YamlNode& node, const std::string& robot_path,
                          bool in_layers = false) {
  // Layers: sources applied in order; later ones win on the joints they drive.
  if (auto t = node.find("type"); t && t->is_scalar() && t->as_string() == "layers") {
    if (in_layers) t->fail("layers cannot be nested");
    node.allow_only({"type", "layers"});
    MotionConfig motion;
    motion.type = "layers";
    motion.where = node.location();
    const YamlNode list = node.at("layers");
    const auto items = list.items();
    if (items.empty()) list.fail("expected at least one motion source, found an empty list");
    if (items.size() > kMaxMotionLayers) {
      list.fail("expected at most " + std::to_string(kMaxMotionLayers) + " motion sources, found " +
                std::to_string(items.size()));
    }
    for (const YamlNode& item : items)
      motion.layers.push_back(parse_motion(item, robot_path, true));
    return motion;
  }
  if (auto t = node.find("type"); t && t->is_scalar() && t->as_string() == "head") {
    MotionConfig motion;
    motion.type = "head";
    motion.where = node.location();
    motion.key = node.path();
    motion.head =
        std::make_shared<head::HeadMotionConfig>(head::parse_head_motion(node, robot_path));
    motion.file = motion.head->model;
    return motion;
  }
  node.allow_only({"type", "file"});
  MotionConfig motion;
  const YamlNode type = node.at("type");
  motion.type = type.as_string();
  if (motion.type != "gait" && motion.type != "show") {
    type.fail("unknown motion type " + found(type) + " (supported: gait, head, show, layers)");
  }

  const YamlNode file = node.at("file");
  const std::string given = file.as_string();
  if (given.empty()) file.fail("expected a file path, found \"\"");
  motion.where = file.location();
  motion.key = file.path();

  // Not normalised: "a/b/../c" stays correct when b is a symlink.
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(robot_path).parent_path();
  const fs::path resolved = fs::path(given).is_absolute() ? fs::path(given) : folder / given;
  motion.file = resolved.string();

  const std::string problem = input_file_problem(motion.file);
  const std::string where =
      given == motion.file ? quote_path(given)
                           : quote_path(given) + " (resolved against the robot file's folder to " +
                                 quote_path(motion.file) + ")";
  if (problem == kFileMissing) file.fail("file not found: " + where);
  if (!problem.empty()) file.fail(where + " " + problem);
  return motion;
}

}  // namespace

RobotConfig load_robot_config(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  require_robot_file(root);
  root.allow_only({"name", "loop", "safety", "buses", "joints", "motion", "model", "imus"});

  RobotConfig config;
  config.file = path;

  const YamlNode name = root.at("name");
  config.name = name.as_string();
  if (config.name.empty()) name.fail("expected a robot name, found \"\"");

  const YamlNode loop = root.at("loop");
  loop.allow_only({"rate_hz"});
  config.rate_hz = loop.at("rate_hz").as_double_in(1.0, 10000.0);

  const auto safety = root.find("safety");
  if (safety) config.safety = parse_safety(*safety, config.rate_hz);

  const YamlNode buses = root.at("buses");
  config.buses = parse_buses(buses, config.rate_hz);
  check_bus_timeouts(buses, config, safety);
  parse_joints(root.at("joints"), config);
  config.joints_where = key_location(root, "joints");
  check_sim_ids(buses, config);
  check_bus_load(loop.at("rate_hz"), config);
  // A bus without devices is almost always a typo in some actuator.bus, and
  // opening its port would fail or grab a line for nothing.
  for (const auto& bus : config.buses) {
    if (bus.actuators.empty()) {
      throw InputError(bus.where, key_path(buses, bus.name),
                       "no joint is bound to this bus (bind joints with actuator.bus: " + bus.name +
                           ", or remove the bus)");
    }
  }

  if (auto imus = root.find("imus")) config.imus = parse_imus(*imus, config.rate_hz);
  if (config.safety.tilt_limit_rad > 0.0 && config.imus.empty()) {
    safety->at("tilt_limit_deg").fail("the tilt watch needs an IMU; add one under imus:");
  }
  config.motion = parse_motion(root.at("motion"), path);
  if (auto model = root.find("model")) {
    // Whether MuJoCo can load it is checked where the model is loaded.
    config.model = resolve_file(*model, path);
    config.model_where = model->location();
  }
  return config;
}

}  // namespace animrt
