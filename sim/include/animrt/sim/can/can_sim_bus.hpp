#pragma once
// Simulated devices of one CAN bus ("mit" motors or "cia402" drives) served
// on a background thread over a CanFrameTransport:
// - in-process (the default): attached to the virtual bus named after the
//   bus's interface; endpoint() is "virtual:IFACE", which make_bus opens. The
//   virtual bus reports the simulation's clock, so lockstep runs are
//   deterministic; on a lockstep clock the host's reads wait until these
//   devices have served every frame at the clock's time
//   (VirtualCanBus::attach_lockstep_device), never on the wall clock.
// - SocketCAN (`animrt sim`, see set_can_sim_attach): attached to the real
//   interface (e.g. vcan0 in the HIL guest); endpoint() is the interface, and
//   any SocketCAN client (the runtime, candump, python-can) talks to them.
// Several simulated buses may share one interface.

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/can/can_transport.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/thread_priority.hpp"
#include "animrt/sim/can/can_node.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt::sim {

enum class CanSimAttach : std::uint8_t { in_process, socketcan };
// Where CAN buses built by make_simulated_bus attach (process-wide).
void set_can_sim_attach(CanSimAttach attach);
CanSimAttach can_sim_attach();

class CanSimBus final : public SimulatedBus {
 public:
  // Throws InputError for an unknown protocol, DeviceError if the SocketCAN
  // interface cannot be opened.
  CanSimBus(const BusConfig& config, const Clock& clock, CanSimAttach attach);
  ~CanSimBus() override;
  CanSimBus(const CanSimBus&) = delete;
  CanSimBus& operator=(const CanSimBus&) = delete;

  const std::string& endpoint() const override { return endpoint_; }
  std::string describe() const override;
  void start() override;
  void stop() override;
  std::string raise_priority(int priority) override { return set_fifo_priority(thread_, priority); }
  void set_device_responding(int device_id, bool responding) override;
  void set_device_hardware_error(int device_id, std::uint8_t error_bits) override;
  // The device's next `answers` batches of frames (every one while answers
  // < 0), answers or heartbeats, leave `delay_ns` of real time late: the
  // devices' thread ran late, as on a loaded machine.
  void set_device_answer_delay(int device_id, Nanos delay_ns, int answers = -1) override;
  // The device's health model (CiA 402 drives, MIT motors), at once.
  void inject_device_health(int device_id, const SimHealthInjection& change) override;
  double device_position(int device_id) const override;

  // CAN-specific fault injection: power-cycle one device (it restarts with
  // its defaults and announces itself with a boot-up message, CiA 402).
  void reboot_device(int device_id);
  // Whether a device's guard against a dead host has fired (CanNode::guard_fired).
  bool device_guard_fired(int device_id) const;
  // The in-process virtual bus (nullptr on SocketCAN), e.g. for bus-off.
  const std::shared_ptr<VirtualCanBus>& virtual_bus() const { return virtual_bus_; }
  std::uint64_t frames_handled() const { return frames_handled_.load(); }

 private:
  void serve();
  // How late (real time) the frames `node` just added to out_ leave.
  Nanos lateness(const CanNode& node, std::size_t out_before);
  CanNode& node(int device_id) const;
  void flush(FrameList& out);

  BusConfig config_;
  const Clock& clock_;
  std::string endpoint_;
  std::shared_ptr<VirtualCanBus> virtual_bus_;
  std::unique_ptr<CanFrameTransport> transport_;
  LockstepCanPort* lockstep_port_ = nullptr;  // transport_ on a lockstep clock
  mutable std::mutex mutex_;                  // guards nodes_ and the transport's send side
  std::vector<std::unique_ptr<CanNode>> nodes_;
  std::vector<std::vector<CanNode*>> listeners_;  // per CAN id (11 bits)
  FrameList out_;                                 // serving thread only
  struct Delay {
    int device_id;
    Nanos ns;
    int answers;  // < 0: every one
  };
  std::vector<Delay> delays_;  // guarded by mutex_
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> frames_handled_{0};
};

std::unique_ptr<SimulatedBus> make_can_sim_bus(const BusConfig& config, const Clock& clock);

}  // namespace animrt::sim
