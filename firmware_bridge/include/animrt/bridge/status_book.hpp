#pragma once
// The per-device status every bus keeps (DeviceStatus, one entry per
// configured actuator), and the one place its counters and health change,
// so every protocol counts a timeout, a damaged answer or a device fault
// the same way. Also names the bus and its devices in messages.
//
// The book is written by the bus alone; the runtime reads it through
// ActuatorBus::devices() (and sets `faulted`). Nothing here allocates after
// construction except prefix() and describe(), which are for lifecycle
// messages only.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"

namespace animrt {

class StatusBook {
 public:
  StatusBook() = default;
  // One entry per config.actuators, with its device id. `where` is where the
  // bus is (a port, a CAN interface, host:port); `noun` names one device in
  // messages ("id", "node", "slave").
  StatusBook(const BusConfig& config, std::string where, std::string noun = "id");

  // Every entry back to a fresh DeviceStatus with its device id (configure()).
  void reset();
  void set_device_id(std::size_t device, int id) { status_[device].device_id = id; }

  std::size_t size() const { return status_.size(); }
  DeviceStatus& operator[](std::size_t device) { return status_[device]; }
  const DeviceStatus& operator[](std::size_t device) const { return status_[device]; }
  std::span<DeviceStatus> devices() { return status_; }
  std::span<const DeviceStatus> devices() const { return status_; }
  bool faulted(std::size_t device) const { return status_[device].faulted; }

  // One request that expected an answer from the device.
  void asked(std::size_t device) { ++status_[device].transactions; }
  // It answered with usable data; `fault`: the answer reports a device fault.
  void answered(std::size_t device, bool fault = false) {
    status_[device].health = fault ? DeviceHealth::hardware_error : DeviceHealth::ok;
  }
  // No answer within the timeout.
  void timed_out(std::size_t device) {
    ++status_[device].timeouts;
    status_[device].health = DeviceHealth::timeout;
  }
  // A damaged answer (`checksum`: its CRC or checksum was wrong), or a
  // malformed, truncated or unexpected one in place of its answer.
  void garbled(std::size_t device, bool checksum = false) {
    DeviceStatus& st = status_[device];
    ++(checksum ? st.crc_errors : st.protocol_errors);
    st.health = DeviceHealth::protocol_error;
  }
  // An answer the device sent that answers nothing asked now (a late one to
  // an earlier request): counted, no verdict on its health.
  void stray(std::size_t device) { ++status_[device].protocol_errors; }
  // The device refused the request (a status error number, a wrong data
  // length); `fault`: the answer also reports a device fault.
  void rejected(std::size_t device, bool fault = false) {
    ++status_[device].protocol_errors;
    status_[device].health = fault ? DeviceHealth::hardware_error : DeviceHealth::protocol_error;
  }
  // The device reports a fault (an alert bit, fault bits, a fault register).
  // The health follows with answered(device, true) or rejected(device, true).
  void fault_reported(std::size_t device) { ++status_[device].hardware_errors; }
  // A fault register read: counted, kept, and the health says so.
  void hardware_fault(std::size_t device, std::uint8_t fault_register) {
    DeviceStatus& st = status_[device];
    ++st.hardware_errors;
    st.hardware_error_status = fault_register;
    st.health = DeviceHealth::hardware_error;
  }
  // A protocol-level exception answer (Modbus), its code kept.
  void exception(std::size_t device, std::uint8_t code) {
    DeviceStatus& st = status_[device];
    ++st.exceptions;
    st.last_error_byte = code;
    st.health = DeviceHealth::protocol_error;
  }

  // "bus legs (/dev/ttyUSB0): "
  std::string prefix() const;
  // "id 5 (lf_ankle)"
  std::string describe(std::size_t device) const;
  // describe() of several devices, comma separated.
  template <class Pick>
  std::string list(Pick&& pick) const {
    std::string out;
    for (std::size_t i = 0; i < status_.size(); ++i) {
      if (pick(i)) out += (out.empty() ? "" : ", ") + describe(i);
    }
    return out;
  }

 private:
  std::vector<DeviceStatus> status_;
  std::vector<int> ids_;
  std::vector<std::string> joints_;
  std::string name_;
  std::string where_;
  std::string noun_ = "id";
};

}  // namespace animrt
