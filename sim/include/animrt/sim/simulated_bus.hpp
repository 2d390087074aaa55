#pragma once
// Simulated devices of one bus: firmware that speaks the bus's real wire
// protocol on the device side of a pseudo-terminal (or other endpoint), so the
// runtime drives it through exactly the code that drives hardware.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/lockstep_line.hpp"
#include "animrt/core/clock.hpp"

namespace animrt {

class SimulatedBus {
 public:
  virtual ~SimulatedBus() = default;
  // Where a client connects, e.g. "/dev/pts/7". Valid after construction.
  virtual const std::string& endpoint() const = 0;
  // One line for `animrt sim`, e.g. "serial legs /dev/pts/7".
  virtual std::string describe() const = 0;
  // Serve on a background thread until stop() or destruction.
  virtual void start() = 0;
  virtual void stop() = 0;
  // Puts the serving thread (after start()) at SCHED_FIFO `priority`, so
  // that a busy host does not make the devices miss their own deadlines;
  // "" when done, otherwise why not.
  virtual std::string raise_priority(int priority) = 0;
  // Fault injection: a device that is not responding ignores every packet.
  virtual void set_device_responding(int device_id, bool responding) = 0;
  // Fault injection: a device with hardware error bits set reports them in its
  // hardware error register and sets the alert bit of every status packet.
  virtual void set_device_hardware_error(int device_id, std::uint8_t error_bits) = 0;
  // Fault injection: the device's next `answers` answers (every one while
  // answers < 0) leave `delay_ns` of real time late; 0 switches it off.
  // Throws std::logic_error where the devices do not model it (the
  // Dynamixel servos, the CAN drives and motors and the Modbus drives do).
  virtual void set_device_answer_delay(int device_id, Nanos delay_ns, int answers = -1) {
    (void)device_id;
    (void)delay_ns;
    (void)answers;
    throw std::logic_error("simulated bus " + endpoint() + ": answer delay is not modelled");
  }
  // Fault injection: a change to the device's health model at once (its
  // temperature, a blocked joint, its supply, its error bits; `at_s` is
  // ignored). Throws std::logic_error where the devices do not model it.
  virtual void inject_device_health(int device_id, const SimHealthInjection& change) {
    (void)device_id;
    (void)change;
    throw std::logic_error("simulated bus " + endpoint() + ": device health is not modelled");
  }
  // On a lockstep clock: the line the host's transport follows, so that it
  // knows when the devices have answered all they will (lockstep_line.hpp);
  // nullptr on the wall clock, and where the devices keep no such line.
  virtual std::shared_ptr<LockstepLine> lockstep_line() const { return nullptr; }
  // Position of a device in radians (through its binding), for tests.
  virtual double device_position(int device_id) const = 0;

  // Commissioning: what a person does to a serial servo on the bench (the
  // control interface of `animrt sim`). Devices are named by the id the
  // robot file gives them (std::out_of_range for one not on this bus),
  // whatever their ID register says now. Buses whose devices do not model
  // it throw std::logic_error.
  struct ServoReadout {
    std::int32_t ticks = 0;  // Present Position, raw
    bool torque = false;
    int id = 0;    // the ID register
    int baud = 0;  // the Baud Rate register, in bits per second
  };
  // Turns the shaft to raw position `ticks` (as Present Position reads it),
  // as a hand turns a limp servo (or one held by a weak torque: see the
  // servo's own model); throws std::logic_error("torque is on") against a
  // torque stronger than a hand.
  virtual void hand_move(int device_id, std::int32_t ticks) {
    (void)device_id;
    (void)ticks;
    throw std::logic_error("simulated bus " + endpoint() + ": hands are not modelled");
  }
  // A test aid, not something a servo or a person does: a hand that turns
  // the shaft (as hand_move) to ticks[0] at once, then on to each next
  // position once the servo has answered `reads_per_step` reads of its
  // Present Position at the one before, so that a host reading it sees
  // every step whatever the load on the machine. It ends at the last
  // position (held, as by hand_move); hand_move or a new path replaces
  // it, torque too strong for a hand ends it. Throws as hand_move, and
  // std::invalid_argument for no positions or reads_per_step < 1.
  virtual void hand_path(int device_id, const std::vector<std::int32_t>& ticks,
                         int reads_per_step) {
    (void)device_id;
    (void)ticks;
    (void)reads_per_step;
    throw std::logic_error("simulated bus " + endpoint() + ": hand paths are not modelled");
  }
  virtual ServoReadout servo_readout(int device_id) const {
    (void)device_id;
    throw std::logic_error("simulated bus " + endpoint() + ": servo readout is not modelled");
  }
  // Connects (powers up, RAM at its defaults) or disconnects the index-th
  // device of the bus (0-based, the robot file's order); an unplugged device
  // hears and says nothing. std::out_of_range for an index past the end.
  virtual void set_device_plugged(std::size_t index, bool plugged) {
    (void)index;
    (void)plugged;
    throw std::logic_error("simulated bus " + endpoint() + ": plugging is not modelled");
  }
};

namespace sim {
class JointPhysics;
class ServoStateFile;
}  // namespace sim

// How simulated serial servos (Dynamixel, Feetech) start: as the robot file
// configures them (ids and baud from it), or as from the factory.
struct ServoStartup {
  // EEPROM at factory settings (ID 1; Dynamixel 57600 baud, Feetech 1 Mbaud)
  // and only the first device of each bus plugged in: a user plugs in one
  // new servo at a time and gives it its id.
  bool factory = false;
  // Restores each servo's EEPROM from it (over the above) and saves it there
  // whenever it changes (outlives the buses).
  sim::ServoStateFile* state = nullptr;
  // A servo answers only packets sent at its own baud rate: the one the host
  // set on the pseudo-terminal. `any_baud` lets every servo hear every
  // packet, for a line whose baud setting never reaches the simulator (a
  // QEMU-emulated UART caps it at 115200 whatever the guest uses).
  bool any_baud = false;
};

// Builds the simulated devices for config.protocol ("dynamixel2": N X-series
// servos behind one pty). Motor models read time from `clock`, so a lockstep
// run with a ManualClock is deterministic. With `physics` (dynamixel2 only;
// InputError for other protocols) the servos take their motor state from it.
std::unique_ptr<SimulatedBus> make_simulated_bus(const BusConfig& config, const Clock& clock,
                                                 sim::JointPhysics* physics = nullptr,
                                                 const ServoStartup& startup = {});

}  // namespace animrt
