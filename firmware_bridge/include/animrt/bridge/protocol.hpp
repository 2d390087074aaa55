#pragma once
// A protocol module holds everything protocol-specific about a bus, from the
// robot file to the wire: which keys a bus and an actuator of that protocol
// take (and their checks), and how the bus is built. The runtime's config
// reader and bus factory only dispatch here, so adding a device means adding
// a module (and a simulated device in sim/), not editing the runtime.

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {

class Protocol {
 public:
  virtual ~Protocol() = default;
  virtual std::string_view name() const = 0;

  // Whether buses of this protocol may share their port with other buses
  // that say so too (a CAN interface carries several protocols, told apart
  // by frame ids); a serial line belongs to one bus.
  virtual bool shares_port() const { return false; }

  // Whether its actuators can be bound to prismatic joints (positions in
  // metres); the others drive revolute joints only.
  virtual bool drives_prismatic() const { return false; }

  // Bus keys of this protocol besides `protocol` and `sim` (read by the
  // runtime), in the order error messages list them.
  virtual std::span<const std::string_view> bus_keys() const = 0;
  // Reads those keys into `bus` (name, protocol, where and sim are set).
  virtual void read_bus(const YamlNode& node, BusConfig& bus) const = 0;

  // Actuator keys besides `bus`, in message order.
  virtual std::span<const std::string_view> actuator_keys() const = 0;
  // Reads an actuator binding of `joint` on `bus` (whose actuators so far are
  // in bus.actuators) and checks that the joint's limits, given in
  // `limits_node`, are positions the device can take.
  virtual void read_actuator(const YamlNode& node, const JointSpec& joint,
                             const YamlNode& limits_node, const BusConfig& bus,
                             ActuatorBinding& out) const = 0;

  // Bits on the wire for one loop cycle of `bus` with its actuators (framing
  // and answers included, an estimate on the high side), so the loader can
  // refuse a loop rate the bus cannot carry at bus.baud. 0: not estimated
  // (a network link).
  virtual double wire_bits_per_cycle(const BusConfig& bus) const {
    (void)bus;
    return 0.0;
  }
  // Of those, the bits of the cycle's read (requests and answers), which
  // must be back within the loop's read budget, and how many transactions
  // the read takes (each costs a measured overhead beyond its bits). 0 bits:
  // not estimated.
  virtual double read_wire_bits_per_cycle(const BusConfig& bus) const {
    (void)bus;
    return 0.0;
  }
  virtual int read_transactions_per_cycle(const BusConfig& bus) const {
    (void)bus;
    return 1;
  }

  // What stops this bus's actuators when the host dies (kill -9, a crash, a
  // power cut), for `animrt validate`, when the user should hear of it: no
  // device-side guard, or one that must be set outside animrt. Empty: the
  // bus sets its guard itself, nothing to say.
  virtual std::string device_guard_note(const BusConfig& bus) const {
    (void)bus;
    return {};
  }

  // Opens the bus (transport included). Throws DeviceError.
  virtual std::unique_ptr<ActuatorBus> make_bus(const BusConfig& bus) const = 0;
};

// The registered protocols; nullptr for an unknown name.
const Protocol* find_protocol(std::string_view name);
// "dynamixel2, ..." for messages.
std::string supported_protocols();

}  // namespace animrt
