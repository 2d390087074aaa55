#include "animrt/sim/can/can_sim_bus.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/socketcan.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/can/cia402_drive_node.hpp"
#include "animrt/sim/can/mit_motor_node.hpp"

namespace animrt::sim {
namespace {

std::atomic<CanSimAttach> g_attach{CanSimAttach::in_process};
constexpr auto kPollInterval = std::chrono::milliseconds(2);

}  // namespace

void set_can_sim_attach(CanSimAttach attach) { g_attach.store(attach); }
CanSimAttach can_sim_attach() { return g_attach.load(); }

CanSimBus::CanSimBus(const BusConfig& config, const Clock& clock, CanSimAttach attach)
    : config_(config), clock_(clock) {
  const Nanos now = clock.now();
  for (const ActuatorBinding& b : config_.actuators) {
    if (config_.protocol == "mit") {
      // The motors' CAN timeout is what the bus says their setup menu holds.
      const MitBusOptions options = options_of<MitBusOptions>(config_.options);
      nodes_.push_back(std::make_unique<MitMotorNode>(b, options.master_id, config_.sim, now,
                                                      options.device_watchdog_ms));
    } else if (config_.protocol == "cia402") {
      nodes_.push_back(std::make_unique<Cia402DriveNode>(b, config_.sim, now));
    } else {
      throw InputError(config_.where, "protocol",
                       "no simulated CAN devices for protocol '" + elide(config_.protocol) + "'");
    }
  }
  listeners_.resize(CAN_SFF_MASK + 1);
  std::vector<can_filter> filters;
  for (const auto& n : nodes_) {
    for (canid_t id : n->listens_to()) {
      auto& list = listeners_[id & CAN_SFF_MASK];
      if (list.empty()) filters.push_back({id, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG});
      list.push_back(n.get());
    }
  }
  if (attach == CanSimAttach::in_process) {
    const std::string name = config_.port.starts_with(kVirtualCanPrefix)
                                 ? config_.port.substr(kVirtualCanPrefix.size())
                                 : config_.port;
    virtual_bus_ = VirtualCanBus::named(name);
    virtual_bus_->set_clock(&clock_);
    if (dynamic_cast<const ManualClock*>(&clock_) != nullptr) {
      // Lockstep: the host's reads wait for these devices, not the wall clock.
      auto port = virtual_bus_->attach_lockstep_device();
      lockstep_port_ = port.get();
      transport_ = std::move(port);
    } else {
      transport_ = virtual_bus_->attach();
    }
    endpoint_ = std::string(kVirtualCanPrefix) + name;
  } else {
    transport_ = open_socketcan(config_.port);
    endpoint_ = config_.port;
  }
  transport_->set_filters(filters);
  out_.reserve(64);
}

CanSimBus::~CanSimBus() {
  stop();
  // The virtual bus may outlive this simulation; it must not keep our clock.
  if (virtual_bus_) virtual_bus_->set_clock(nullptr);
}

std::string CanSimBus::describe() const {
  return "can " + config_.name + " " + endpoint_ + " (" + std::to_string(nodes_.size()) + " " +
         (config_.protocol == "mit" ? "MIT motors" : "CiA 402 drives") + ")";
}

void CanSimBus::flush(FrameList& out) {
  for (const can_frame& f : out) transport_->send(f);
  out.clear();
}

void CanSimBus::start() {
  if (thread_.joinable()) return;
  stop_ = false;
  if (lockstep_port_) lockstep_port_->serving(true);
  thread_ = std::thread([this] { serve(); });
}

void CanSimBus::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (lockstep_port_) lockstep_port_->serving(false);
}

void CanSimBus::serve() {
  can_frame frame;
  while (!stop_.load()) {
    const bool got = transport_->receive(frame, kPollInterval);
    std::unique_lock lock(mutex_);
    const Nanos now = clock_.now();
    Nanos late = 0;
    if (got) {
      ++frames_handled_;
      for (CanNode* n : listeners_[frame.can_id & CAN_SFF_MASK]) {
        const std::size_t before = out_.size();
        n->handle(frame, now, out_);
        late = std::max(late, lateness(*n, before));
      }
    }
    // Time-driven behaviour (heartbeats, the guards against a dead host)
    // must not wait for a quiet bus.
    for (const auto& n : nodes_) {
      const std::size_t before = out_.size();
      n->poll(now, out_);
      late = std::max(late, lateness(*n, before));
    }
    if (late > 0) {
      lock.unlock();
      std::this_thread::sleep_for(std::chrono::nanoseconds(late));
      lock.lock();
    }
    flush(out_);
    if (lockstep_port_) lockstep_port_->served(now);
  }
}

Nanos CanSimBus::lateness(const CanNode& node, std::size_t out_before) {
  if (delays_.empty() || out_.size() == out_before) return 0;
  for (Delay& d : delays_) {
    if (d.device_id != node.device_id() || d.answers == 0) continue;
    if (d.answers > 0) --d.answers;
    return d.ns;
  }
  return 0;
}

void CanSimBus::set_device_answer_delay(int device_id, Nanos delay_ns, int answers) {
  std::lock_guard lock(mutex_);
  node(device_id);  // std::out_of_range for a device not on this bus
  std::erase_if(delays_, [&](const Delay& d) { return d.device_id == device_id; });
  if (delay_ns > 0 && answers != 0) delays_.push_back({device_id, delay_ns, answers});
}

CanNode& CanSimBus::node(int device_id) const {
  for (const auto& n : nodes_) {
    if (n->device_id() == device_id) return *n;
  }
  throw std::out_of_range("no simulated CAN device " + std::to_string(device_id) + " on bus " +
                          config_.name);
}

void CanSimBus::set_device_responding(int device_id, bool responding) {
  std::lock_guard lock(mutex_);
  node(device_id).set_responding(responding);
}

void CanSimBus::set_device_hardware_error(int device_id, std::uint8_t error_bits) {
  std::lock_guard lock(mutex_);
  FrameList out;
  node(device_id).set_fault(error_bits, clock_.now(), out);
  flush(out);
}

void CanSimBus::inject_device_health(int device_id, const SimHealthInjection& change) {
  std::lock_guard lock(mutex_);
  FrameList out;
  node(device_id).inject_health(change, clock_.now(), out);
  flush(out);
}

void CanSimBus::reboot_device(int device_id) {
  std::lock_guard lock(mutex_);
  FrameList out;
  node(device_id).reboot(clock_.now(), out);
  flush(out);
}

bool CanSimBus::device_guard_fired(int device_id) const {
  std::lock_guard lock(mutex_);
  return node(device_id).guard_fired();
}

double CanSimBus::device_position(int device_id) const {
  std::lock_guard lock(mutex_);
  return node(device_id).joint_position(clock_.now());
}

std::unique_ptr<SimulatedBus> make_can_sim_bus(const BusConfig& config, const Clock& clock) {
  return std::make_unique<CanSimBus>(config, clock, can_sim_attach());
}

}  // namespace animrt::sim
