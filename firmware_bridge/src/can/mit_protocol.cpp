// "mit": MIT mini-cheetah mode motors as a protocol module.

#include <cmath>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/can_protocols.hpp"
#include "animrt/bridge/can/mit_bus.hpp"
#include "can_config.hpp"

namespace animrt {
namespace {

constexpr std::string_view kMitBusKeys[] = {"interface", "bitrate", "timeout_ms", "master_id",
                                            "device_watchdog_ms"};

// The firmware counts its CAN timeout in current-loop cycles (40 kHz) in a
// 32-bit setting; a minute is far past any use.
constexpr int kMaxTimeoutMs = 60'000;
constexpr std::string_view kMitActuatorKeys[] = {"id",
                                                 "model",
                                                 "kp",
                                                 "kd",
                                                 "zero_deg",
                                                 "direction",
                                                 "position_max_rad",
                                                 "velocity_max_rad_s",
                                                 "torque_max_nm"};

class Mit final : public Protocol {
 public:
  std::string_view name() const override { return "mit"; }
  bool shares_port() const override { return true; }
  std::span<const std::string_view> bus_keys() const override { return kMitBusKeys; }
  std::span<const std::string_view> actuator_keys() const override { return kMitActuatorKeys; }

  void read_bus(const YamlNode& node, BusConfig& bus) const override {
    can_config::read_common_bus(node, bus);
    MitBusOptions options;
    if (auto n = node.find("master_id"))
      options.master_id = static_cast<canid_t>(n->as_int_in(0, MitBus::kMaxId));
    // Not settable over CAN: it states what each motor's setup menu holds,
    // and the simulated motors use it as theirs.
    options.device_watchdog_ms =
        can_config::read_device_watchdog(node, bus, kMaxTimeoutMs, "the motors' CAN timeout");
    bus.options = options;
  }

  void read_actuator(const YamlNode& node, const JointSpec& joint, const YamlNode& limits_node,
                     const BusConfig& bus, ActuatorBinding& out) const override {
    const MitBusOptions bus_options = options_of<MitBusOptions>(bus.options);
    const YamlNode id_node = node.at("id");
    const std::int64_t id = id_node.as_int();
    if (id < 1 || id > MitBus::kMaxId || id == bus_options.master_id) {
      id_node.fail("expected a motor id from 1 to " + std::to_string(MitBus::kMaxId) +
                   ", other than the bus's master_id " + std::to_string(bus_options.master_id) +
                   ", found " + id_node.describe());
    }
    for (const auto& other : bus.actuators) {
      if (other.device_id == id) {
        id_node.fail("motor id " + std::to_string(id) + " is already used by joint " + other.joint +
                     " on bus " + bus.name);
      }
    }
    out.device_id = static_cast<int>(id);

    MitMotorOptions m;
    const YamlNode model = node.at("model");
    m.model = model.as_string();
    const mit::Ranges* ranges = mit::find_model(m.model);
    if (!ranges) {
      model.fail("unknown motor model " + model.describe() + " (known: " + mit::supported_models() +
                 ")");
    }
    m.ranges = *ranges;
    if (auto n = node.find("position_max_rad")) {
      m.ranges.p_max = n->as_double_in(0.1, 1000.0);
      m.ranges.p_min = -m.ranges.p_max;
    }
    if (auto n = node.find("velocity_max_rad_s")) {
      m.ranges.v_max = n->as_double_in(0.1, 1000.0);
      m.ranges.v_min = -m.ranges.v_max;
    }
    if (auto n = node.find("torque_max_nm")) {
      m.ranges.t_max = n->as_double_in(0.01, 10000.0);
      m.ranges.t_min = -m.ranges.t_max;
    }
    m.kp = node.at("kp").as_double_in(m.ranges.kp_min, m.ranges.kp_max);
    m.kd = node.at("kd").as_double_in(m.ranges.kd_min, m.ranges.kd_max);
    if (auto n = node.find("zero_deg")) m.zero_rad = deg_to_rad(n->as_double_in(-3600.0, 3600.0));
    if (auto n = node.find("direction")) out.direction = can_config::read_direction(*n);

    // The joint's limits must be positions the packed command can carry.
    const double a = m.to_motor(joint.limits.min_position, out.direction);
    const double b = m.to_motor(joint.limits.max_position, out.direction);
    m.min_motor_rad = std::min(a, b);
    m.max_motor_rad = std::max(a, b);
    const auto check = [&](const char* key, double joint_rad) {
      const double motor = m.to_motor(joint_rad, out.direction);
      if (motor < m.ranges.p_min || motor > m.ranges.p_max) {
        limits_node.at(key).fail(
            format_number(rad_to_deg(joint_rad)) + " deg maps to motor position " +
            format_number(motor) + " rad (zero_deg " + format_number(rad_to_deg(m.zero_rad)) +
            ", direction " + std::to_string(out.direction) + "), outside the " + m.model +
            " position range +-" + format_number(m.ranges.p_max) + " rad");
      }
    };
    check("min_deg", joint.limits.min_position);
    check("max_deg", joint.limits.max_position);
    out.ticks_per_rad = 1.0;
    out.zero_ticks = 0;
    out.options = m;
  }

  // Per motor a command and a reply frame of 8 data bytes (CAN 2.0A, 47 + 64
  // bits and worst-case bit stuffing).
  double wire_bits_per_cycle(const BusConfig& bus) const override {
    const double frame = 47.0 + 64.0 + std::floor((34.0 + 64.0 - 1.0) / 4.0);
    return 2.0 * frame * static_cast<double>(bus.actuators.size());
  }

  // The guard lives in each motor's setup menu: always worth a line.
  std::string device_guard_note(const BusConfig& bus) const override {
    const int ms = options_of<MitBusOptions>(bus.options).device_watchdog_ms;
    if (ms == 0) {
      return "no device-side guard (device_watchdog_ms: off): if the host dies, the motors keep "
             "their last command (position, gains, torque)";
    }
    return "the motors go limp " + std::to_string(ms) +
           " ms after the last command only if each motor's CAN timeout is set to that in its "
           "serial setup menu (" +
           std::to_string(ms * (mit::kCurrentLoopHz / 1000)) + " cycles at " +
           std::to_string(mit::kCurrentLoopHz / 1000) +
           " kHz): animrt cannot set or read it over CAN";
  }

  std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config) const override {
    return std::make_unique<MitBus>(config, open_bus_can(config));
  }
};

}  // namespace

const Protocol& mit_protocol() {
  static const Mit protocol;
  return protocol;
}

}  // namespace animrt
