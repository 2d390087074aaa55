#include "animrt/runtime/robot_config.hpp"

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
#include "animrt/core/yaml_doc.hpp"

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

SafetyConfig parse_safety(const YamlNode& node) {
  node.allow_only({"watchdog_timeout_s", "start_ramp_s", "stop_ramp_s"});
  SafetyConfig safety;
  if (auto n = node.find("watchdog_timeout_s")) {
    safety.watchdog_timeout_s = n->as_positive_double();
  }
  if (auto n = node.find("start_ramp_s")) safety.start_ramp_s = n->as_double_in(0.0, 60.0);
  if (auto n = node.find("stop_ramp_s")) safety.stop_ramp_s = n->as_double_in(0.0, 60.0);
  return safety;
}

SimBusSettings parse_sim(const YamlNode& node) {
  node.allow_only({"time_constant_s", "max_speed_dps", "wire_time", "return_delay_us"});
  SimBusSettings sim;
  if (auto n = node.find("time_constant_s")) sim.time_constant_s = n->as_positive_double();
  if (auto n = node.find("max_speed_dps")) {
    sim.max_speed_rad_s = deg_to_rad(n->as_positive_double());
  }
  if (auto n = node.find("wire_time")) sim.wire_time = n->as_bool();
  // Dynamixel's Return Delay Time register counts 2 us units, 0..254.
  if (auto n = node.find("return_delay_us")) {
    sim.return_delay_us = static_cast<int>(n->as_int_in(0, 508));
  }
  return sim;
}

BusConfig parse_bus(const std::string& name, const YamlNode& node, const YamlNode& buses) {
  BusConfig bus;
  bus.name = name;
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
  node.allow_only(keys);

  protocol->read_bus(node, bus);
  if (auto n = node.find("sim")) bus.sim = parse_sim(*n);
  return bus;
}

std::vector<BusConfig> parse_buses(const YamlNode& node) {
  const auto entries = node.entries();
  if (entries.empty()) node.fail("expected at least one bus, found an empty map");
  std::vector<BusConfig> buses;
  for (const auto& [name, value] : entries) {
    BusConfig bus = parse_bus(name, value, node);
    // Two buses on one port would fight over the line.
    for (const auto& other : buses) {
      if (other.port == bus.port && !(find_protocol(other.protocol)->shares_port() &&
                                      find_protocol(bus.protocol)->shares_port())) {
        value.at("port").fail("port \"" + bus.port + "\" is already used by bus " + other.name);
      }
    }
    buses.push_back(std::move(bus));
  }
  return buses;
}

JointLimits parse_limits(const YamlNode& node) {
  node.allow_only({"min_deg", "max_deg", "velocity_dps", "acceleration_dps2"});
  const double min_deg = node.at("min_deg").as_double();
  const YamlNode max_node = node.at("max_deg");
  const double max_deg = max_node.as_double();
  if (!(max_deg > min_deg)) {
    max_node.fail("expected a value greater than min_deg (" + num(min_deg) + "), found " +
                  found(max_node));
  }
  JointLimits limits;
  limits.min_position = deg_to_rad(min_deg);
  limits.max_position = deg_to_rad(max_deg);
  limits.max_velocity = deg_to_rad(node.at("velocity_dps").as_positive_double());
  limits.max_acceleration = deg_to_rad(node.at("acceleration_dps2").as_positive_double());
  return limits;
}

double parse_home(const YamlNode& joint, const YamlNode& limits_node) {
  const double min_deg = limits_node.at("min_deg").as_double();
  const double max_deg = limits_node.at("max_deg").as_double();
  const std::string range = num(min_deg) + ".." + num(max_deg);
  const auto home = joint.find("home_deg");
  if (!home) {
    if (min_deg <= 0.0 && 0.0 <= max_deg) return 0.0;
    throw InputError(joint.location(), key_path(joint, "home_deg"),
                     "limits contradict the home pose: home_deg defaults to 0, outside "
                     "min_deg..max_deg (" +
                         range + "); set home_deg inside the limits");
  }
  const double home_deg = home->as_double();
  if (home_deg < min_deg || home_deg > max_deg) {
    home->fail("limits contradict the home pose: expected home_deg within min_deg..max_deg (" +
               range + "), found " + found(*home));
  }
  return deg_to_rad(home_deg);
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
  std::vector<std::string_view> keys{"bus"};
  for (auto key : protocol.actuator_keys()) keys.push_back(key);
  node.allow_only(keys);
  protocol.read_actuator(node, joint, limits_node, bus, binding);
  return bus_index;
}

void parse_joints(const YamlNode& node, RobotConfig& config) {
  const auto entries = node.entries();
  if (entries.empty()) node.fail("expected at least one joint, found an empty map");
  for (const auto& [name, value] : entries) {
    value.allow_only({"limits", "home_deg", "actuator"});
    JointSpec joint;
    joint.name = name;
    const YamlNode limits_node = value.at("limits");
    joint.limits = parse_limits(limits_node);
    joint.home = parse_home(value, limits_node);

    ActuatorBinding binding;
    binding.joint = name;
    binding.joint_index = static_cast<int>(config.joints.size());
    const std::size_t bus_index =
        parse_actuator(value.at("actuator"), joint, limits_node, config.buses, binding);
    config.buses[bus_index].actuators.push_back(binding);
    config.joints.push_back(std::move(joint));
  }
}

MotionConfig parse_motion(const YamlNode& node, const std::string& robot_path, bool in_layers = false) {
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
    for (const YamlNode& item : items) motion.layers.push_back(parse_motion(item, robot_path, true));
    return motion;
  }
  if (auto t = node.find("type"); t && t->is_scalar() && t->as_string() == "head") {
    MotionConfig motion;
    motion.type = "head";
    motion.where = node.location();
    motion.head = std::make_shared<head::HeadMotionConfig>(head::parse_head_motion(node, robot_path));
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

  // Not normalised: "a/b/../c" stays correct when b is a symlink.
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(robot_path).parent_path();
  const fs::path resolved = fs::path(given).is_absolute() ? fs::path(given) : folder / given;
  motion.file = resolved.string();

  std::error_code ec;
  const fs::file_status status = fs::status(resolved, ec);
  const std::string where =
      given == motion.file ? "\"" + given + "\""
                           : "\"" + given + "\" (resolved against the robot file's folder to \"" +
                                 motion.file + "\")";
  if (!fs::exists(status)) file.fail("file not found: " + where);
  if (fs::is_directory(status)) file.fail("expected a file, found a folder: " + where);
  return motion;
}

}  // namespace

RobotConfig load_robot_config(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  root.allow_only({"name", "loop", "safety", "buses", "joints", "motion"});

  RobotConfig config;
  config.file = path;

  const YamlNode name = root.at("name");
  config.name = name.as_string();
  if (config.name.empty()) name.fail("expected a robot name, found \"\"");

  const YamlNode loop = root.at("loop");
  loop.allow_only({"rate_hz"});
  config.rate_hz = loop.at("rate_hz").as_double_in(1.0, 10000.0);

  if (auto safety = root.find("safety")) {
    config.safety = parse_safety(*safety);
    // The watchdog counts in cycles: shorter than two periods, one late answer
    // would already fault a healthy device.
    if (auto watchdog = safety->find("watchdog_timeout_s");
        watchdog && config.safety.watchdog_timeout_s < 2.0 / config.rate_hz) {
      std::ostringstream msg;
      msg << "expected at least two loop periods (" << 2.0 / config.rate_hz << " s at loop.rate_hz "
          << config.rate_hz << "), found \"" << watchdog->as_string() << "\"";
      watchdog->fail(msg.str());
    }
  }

  const YamlNode buses = root.at("buses");
  config.buses = parse_buses(buses);
  parse_joints(root.at("joints"), config);
  // A bus without devices is almost always a typo in some actuator.bus, and
  // opening its port would fail or grab a line for nothing.
  for (const auto& bus : config.buses) {
    if (bus.actuators.empty()) {
      throw InputError(bus.where, key_path(buses, bus.name),
                       "no joint is bound to this bus (bind joints with actuator.bus: " + bus.name +
                           ", or remove the bus)");
    }
  }

  config.motion = parse_motion(root.at("motion"), path);
  return config;
}

}  // namespace animrt
