// What Cia402Bus puts on the wire for the drives' guard against a dead host:
// the SDO writes of 6007h and 1016h:01 at activate (exact bytes), the host's
// heartbeat while the loop cycles, the consumer cleared at deactivate; and
// nothing of it when the guard is off. A simulated drive answers on the
// in-process virtual bus; a third endpoint records every frame.

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"

namespace animrt::cia402_guard_bus_test {
namespace {

constexpr Nanos kMs = 1'000'000;
constexpr canid_t kNode = 32;

using Bytes = std::array<std::uint8_t, 8>;

Bytes bytes_of(const can_frame& f) {
  Bytes b{};
  for (int i = 0; i < 8; ++i) b[i] = f.data[i];
  return b;
}

struct Rig {
  ManualClock clock;
  BusConfig config;
  std::unique_ptr<sim::CanSimBus> sim;
  std::unique_ptr<CanFrameTransport> sniffer;
  std::unique_ptr<Cia402Bus> bus;

  Rig(const std::string& name, int watchdog_ms, AbortConnection action) {
    clock.set(1000 * kMs);
    config.name = "hip";
    config.protocol = "cia402";
    config.port = "virtual:" + name;
    config.timeout_s = 0.5;  // a loaded machine must not time out
    Cia402BusOptions options;
    options.device_watchdog_ms = watchdog_ms;
    options.abort_connection = action;
    config.options = options;
    ActuatorBinding b;
    b.joint = "hip";
    b.joint_index = 0;
    b.device_id = kNode;
    b.ticks_per_rad = 65536 / 6.283185307179586;
    b.zero_ticks = 0;
    config.actuators.push_back(b);
    sim = std::make_unique<sim::CanSimBus>(config, clock, sim::CanSimAttach::in_process);
    sim->start();
    sniffer = VirtualCanBus::named(name)->attach();
    bus = std::make_unique<Cia402Bus>(config, open_can(config.port));
  }
  ~Rig() {
    bus.reset();
    sim->stop();
  }
  // Every frame seen since the last call (the sniffer hears both sides).
  // The host's frames are queued when its send returns; `wait` gives the
  // simulation's answers time to come.
  std::vector<can_frame> drain(std::chrono::microseconds wait = std::chrono::milliseconds(20)) {
    std::vector<can_frame> frames;
    can_frame f;
    while (sniffer->receive(f, wait)) frames.push_back(f);
    return frames;
  }
  // One loop cycle at `t`: SYNC and TPDO, then the RPDO.
  void cycle(Nanos t) {
    clock.set(t);
    std::vector<double> q(1);
    bus->read(q);
    bus->write(q);
  }
};

std::vector<Bytes> sdo_requests(const std::vector<can_frame>& frames) {
  std::vector<Bytes> out;
  for (const can_frame& f : frames) {
    if (f.can_id == canopen::kRsdoBase + kNode && f.len == 8) out.push_back(bytes_of(f));
  }
  return out;
}

bool is_host_heartbeat(const can_frame& f) {
  return f.can_id == 0x77F && f.len == 1 && f.data[0] == 0x05;  // node 127, operational
}

TEST(Cia402GuardBus, ArmingWritesTheAbortOptionThenTheConsumerThenSendsAHeartbeat) {
  Rig rig("guard_bytes", 50, AbortConnection::quick_stop);
  rig.bus->configure();
  rig.drain();
  rig.bus->activate();
  // Nothing of the guard while the buses come up: the other buses' time
  // must not count against the drive.
  const std::vector<can_frame> enabling = rig.drain();
  EXPECT_TRUE(sdo_requests(enabling).empty());
  for (const can_frame& f : enabling) EXPECT_FALSE(is_host_heartbeat(f));
  rig.bus->arm_device_guard();
  const std::vector<can_frame> frames = rig.drain();
  const std::vector<Bytes> sdo = sdo_requests(frames);
  // 6007h:00 = 3 (quick stop), INT16: expedited download of 2 bytes (0x2B).
  const Bytes abort_option{0x2B, 0x07, 0x60, 0x00, 0x03, 0x00, 0x00, 0x00};
  // 1016h:01 = node 127 in bits 23-16, 50 ms in bits 15-0, 4 bytes (0x23).
  const Bytes consumer{0x23, 0x16, 0x10, 0x01, 0x32, 0x00, 0x7F, 0x00};
  ASSERT_GE(sdo.size(), 2u);
  EXPECT_EQ(sdo[0], abort_option);
  EXPECT_EQ(sdo[1], consumer);
  // The first heartbeat right after the consumer was written.
  std::size_t consumer_at = frames.size(), heartbeat_at = frames.size();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].can_id == canopen::kRsdoBase + kNode && bytes_of(frames[i]) == consumer)
      consumer_at = i;
    if (heartbeat_at == frames.size() && is_host_heartbeat(frames[i])) heartbeat_at = i;
  }
  EXPECT_LT(consumer_at, heartbeat_at);
  EXPECT_LT(heartbeat_at, frames.size());
  EXPECT_EQ(rig.bus->drive(0).state, cia402::State::operation_enabled);

  rig.bus->deactivate();
  const std::vector<Bytes> after = sdo_requests(rig.drain());
  const Bytes cleared{0x23, 0x16, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00};
  ASSERT_FALSE(after.empty());
  EXPECT_EQ(after.back(), cleared);
}

TEST(Cia402GuardBus, TheOptionCodeFollowsTheConfiguredReaction) {
  Rig rig("guard_option", 80, AbortConnection::fault);
  rig.bus->configure();
  rig.drain();
  rig.bus->activate();
  rig.bus->arm_device_guard();
  const std::vector<Bytes> sdo = sdo_requests(rig.drain());
  ASSERT_GE(sdo.size(), 2u);
  EXPECT_EQ(sdo[0], (Bytes{0x2B, 0x07, 0x60, 0x00, 0x01, 0x00, 0x00, 0x00}));
  EXPECT_EQ(sdo[1], (Bytes{0x23, 0x16, 0x10, 0x01, 0x50, 0x00, 0x7F, 0x00}));
  rig.bus->deactivate();
}

TEST(Cia402GuardBus, HostHeartbeatsWhileTheLoopCyclesAndNoneAfterDeactivate) {
  Rig rig("guard_heartbeat", 50, AbortConnection::quick_stop);
  rig.bus->configure();
  rig.bus->activate();
  rig.bus->arm_device_guard();
  rig.drain();
  // Two seconds of a 200 Hz loop.
  std::vector<Nanos> sent;
  for (int k = 1; k <= 400; ++k) {
    const Nanos t = 1000 * kMs + k * 5 * kMs;
    rig.cycle(t);
    for (const can_frame& f : rig.drain(std::chrono::microseconds(0))) {
      if ((f.can_id & 0x780) == canopen::kHeartbeatBase && f.can_id != 0x700 + kNode) {
        EXPECT_TRUE(is_host_heartbeat(f));
        sent.push_back(t);
      }
    }
  }
  // On a 12 ms cadence (a quarter of 50 ms), at most once a cycle: 2 s / 12
  // ms of them, never more than 15 ms (the next cycle) apart.
  EXPECT_GE(sent.size(), 165u);
  EXPECT_LE(sent.size(), 167u);
  for (std::size_t i = 1; i < sent.size(); ++i) {
    EXPECT_LE(sent[i] - sent[i - 1], 15 * kMs) << i;
    EXPECT_GE(sent[i] - sent[i - 1], 10 * kMs) << i;
  }
  // The drive, watching, stayed enabled and reported nothing.
  EXPECT_EQ(rig.bus->drive(0).state, cia402::State::operation_enabled);
  EXPECT_EQ(rig.bus->drive(0).emcy_count, 0u);
  EXPECT_FALSE(rig.sim->device_guard_fired(kNode));

  rig.bus->deactivate();
  rig.drain();
  rig.cycle(4000 * kMs);
  for (const can_frame& f : rig.drain()) EXPECT_FALSE(is_host_heartbeat(f));
  // Cleared: a long silence does nothing.
  rig.clock.set(10'000 * kMs);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the simulation polls
  EXPECT_FALSE(rig.sim->device_guard_fired(kNode));
}

TEST(Cia402GuardBus, OffWritesNothingAndSendsNoHeartbeat) {
  Rig rig("guard_off", 0, AbortConnection::quick_stop);
  rig.bus->configure();
  rig.drain();
  rig.bus->activate();
  rig.bus->arm_device_guard();
  for (int k = 1; k <= 100; ++k) rig.cycle(1000 * kMs + k * 5 * kMs);
  rig.bus->deactivate();
  for (const can_frame& f : rig.drain()) {
    EXPECT_FALSE(is_host_heartbeat(f));
    if (f.can_id == canopen::kRsdoBase + kNode) {
      const std::uint16_t index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
      EXPECT_NE(index, 0x1016);
      EXPECT_NE(index, 0x6007);
    }
  }
}

}  // namespace
}  // namespace animrt::cia402_guard_bus_test
