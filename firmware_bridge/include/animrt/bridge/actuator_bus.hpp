#pragma once
// One actuator bus: a protocol spoken over a transport to several devices.
// The runtime drives every bus through this interface and does not know
// whether the other end is hardware or a simulated device.

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/device_health.hpp"

namespace animrt {

enum class DeviceHealth : std::uint8_t { ok, timeout, protocol_error, hardware_error };

const char* to_string(DeviceHealth health);

// Per device, counted since configure(). One writer: the bus that owns the
// device (its transactions, and mark_faulted()). The runtime reads it while
// the bus is idle and keeps what it knows beyond it (requests that threw,
// its watchdog's faults) in its own records.
struct DeviceStatus {
  int device_id = 0;
  DeviceHealth health = DeviceHealth::ok;  // result of the latest transaction
  bool faulted = false;                    // mark_faulted(): the bus skips the device
  std::uint64_t transactions = 0;
  std::uint64_t timeouts = 0;
  std::uint64_t crc_errors = 0;
  std::uint64_t protocol_errors = 0;       // malformed, truncated, wrong id, unexpected packet
  std::uint64_t hardware_errors = 0;       // status packets with the alert / error bits set
  std::uint64_t exceptions = 0;            // Modbus exception responses (code in last_error_byte)
  std::uint8_t last_error_byte = 0;        // status error byte of the last status packet
  std::uint8_t hardware_error_status = 0;  // device's own fault register, when read
  // The measured position is the controller's own output (e.g. a Maestro's
  // ramped pulse for a hobby servo), not a sensor reading.
  bool open_loop = false;
  // Temperature, current, voltage and error bits, when the bus reads them
  // (its `health` key); all NaN otherwise.
  HealthReading reading{};
};

class ActuatorBus {
 public:
  virtual ~ActuatorBus() = default;

  virtual const BusConfig& config() const = 0;

  // Lifecycle. configure(): open the transport, ping every device, read the
  // positions; throws DeviceError naming the device on failure.
  // activate(): torque on. deactivate(): torque off (best effort, never throws).
  virtual void configure() = 0;
  virtual void activate() = 0;
  virtual void deactivate() = 0;
  // The devices' own guard against a dead host (device_watchdog_ms) starts
  // here: called once every bus of the run is active, just before the first
  // cycle, so the time the other buses take to come up is not counted
  // against this bus's devices. Throws DeviceError naming the device.
  virtual void arm_device_guard() {}

  // One cycle. Indexed like config().actuators. read() updates the entries of
  // devices that answered and leaves the others unchanged; write() sends the
  // goal positions (rad, or m for a prismatic joint). Neither allocates, and
  // neither blocks longer than the bus timeout. Devices marked `faulted` are
  // skipped.
  virtual void read(std::span<double> positions) = 0;
  virtual void write(std::span<const double> positions) = 0;

  // The runtime's watchdog has faulted `device` (indexed like
  // config().actuators): read() and write() skip it until the next
  // configure(). Called while no read() or write() runs.
  virtual void mark_faulted(std::size_t device) { devices()[device].faulted = true; }
  // A health fault (overheated, stalled, undervoltage): as mark_faulted, and
  // the device's torque goes off, which the bus does in its next read() (on
  // its own thread: the caller never waits for the line). Buses that cannot
  // address one device alone only mark it.
  virtual void switch_off(std::size_t device) { mark_faulted(device); }

  // Commissioning (a direction jog, a compliant recording): torque on for
  // `device` alone at a weak current, `share` of the device's own current
  // limit, holding its present position; write() then moves it with that
  // weak torque, and a hand can move it. False, and nothing changes, when the
  // device has no current control. deactivate() ends it. Throws DeviceError
  // naming the device.
  virtual bool activate_compliant(std::size_t device, double share) {
    (void)device;
    (void)share;
    return false;
  }
  // Commissioning (calibrate): homes `device` where it rests, torque off,
  // so that from now on, and after a power cycle, its present position
  // there reads `ticks` (a Dynamixel's Homing Offset; a CiA 402 drive's
  // homing). Returns the present position read back afterwards. Throws
  // DeviceError naming the device, also when it cannot be homed this way.
  virtual std::int64_t set_home(std::size_t device, std::int64_t ticks);

  // Whether read() fills DeviceStatus::reading (temperature, current,
  // voltage, error bits) as configured.
  virtual bool reads_health() const { return false; }
  // The device's own name for the error bits or fault code its health
  // reading carries (a drive's "driver overtemperature"); "" for none.
  virtual std::string error_words(std::size_t /*device*/, std::uint32_t /*bits*/) const {
    return {};
  }

  // Per device status, indexed like config().actuators; written by this bus
  // alone (see DeviceStatus).
  virtual std::span<DeviceStatus> devices() = 0;
};

// configure()'s search for its devices. ping(i) asks device i once (with the
// bus's own retries) and returns whether it answered at all. Devices still
// silent are asked again after a pause, for kPingRounds rounds: a servo
// powered up together with the adapter answers only once it has booted, and
// one scheduling hiccup of the machine must not fail a whole start-up.
// Returns, per device, whether it ever answered.
inline constexpr int kPingRounds = 5;
inline constexpr int kPingPauseMs = 40;
std::vector<bool> ping_until_answered(std::size_t devices,
                                      const std::function<bool(std::size_t)>& ping);

// Builds the bus for config.protocol on a transport opened on config.port.
std::unique_ptr<ActuatorBus> make_bus(const BusConfig& config);

}  // namespace animrt
