// A host that dies in the middle of a switch search (a CiA 402 drive homed
// by Cia402Bus::set_home, method 18): with device_watchdog_ms the drive
// watches the host's heartbeat for as long as homing has it enabled, so once
// the host goes silent it faults (EMCY 8130h) and stops within the consumer
// time, instead of searching on until a switch stops it and staying powered.
// The simulated drive is on the in-process virtual bus, its clock advanced
// by the test. The host's death is what a kill leaves: no further frame, no
// deactivate; its thread is frozen inside the bus until the drive has been
// looked at, from the wire, by a client written here. A homing that ends
// normally leaves the consumer off, so the host's later silence is no error.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"

namespace animrt::cia402_homing_guard_test {
namespace {

constexpr Nanos kMs = 1'000'000;
constexpr canid_t kNode = 23;
constexpr double kCountsPerDeg = 100.0;
constexpr int kWatchdogMs = 100;
constexpr int kHostHeartbeatMs = Cia402Bus::host_heartbeat_ms(kWatchdogMs);

// The host's transport, which can die: from then on it sends nothing and
// its receive() blocks until released (then finds nothing). It notes when
// the host last sent its heartbeat.
class MortalTransport final : public CanFrameTransport {
 public:
  explicit MortalTransport(std::unique_ptr<CanFrameTransport> inner) : inner_(std::move(inner)) {}
  const std::string& interface() const override { return inner_->interface(); }
  void set_filters(std::span<const can_filter> filters) override { inner_->set_filters(filters); }
  bool send(const can_frame& frame) override {
    std::lock_guard lock(mutex_);
    if (dead_) return true;
    if ((frame.can_id & CAN_SFF_MASK & ~canid_t{0x7F}) == 0x700) last_heartbeat_ = inner_->now();
    return inner_->send(frame);
  }
  bool receive(can_frame& frame, std::chrono::microseconds timeout) override {
    if (!dead_.load()) return inner_->receive(frame, timeout);
    while (!released_.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return false;
  }
  const CanErrorCounters& errors() const override { return inner_->errors(); }
  bool bus_off() const override { return inner_->bus_off(); }
  Nanos now() const override { return inner_->now(); }
  // After die() returns, no frame of the host's is on its way.
  void die() {
    std::lock_guard lock(mutex_);
    dead_ = true;
  }
  void release() { released_ = true; }
  // Whether a clock at `now` is within one and a half of the host's
  // heartbeat periods of its last heartbeat (or it sent none yet): the
  // test's clock runs on only while the host's thread keeps up, however long
  // a loaded machine holds it off the CPU, so the drive never misses a
  // heartbeat the host would have sent.
  bool keeping_up(Nanos now) const {
    const Nanos last = last_heartbeat_.load();
    return last < 0 || now < last + 3 * kHostHeartbeatMs * kMs / 2;
  }

 private:
  std::unique_ptr<CanFrameTransport> inner_;
  std::atomic<Nanos> last_heartbeat_{-1};
  std::mutex mutex_;
  std::atomic<bool> dead_{false};
  std::atomic<bool> released_{false};
};

BusConfig slide_bus(const std::string& name) {
  BusConfig config;
  config.name = "slide";
  config.protocol = "cia402";
  config.port = "virtual:" + name;
  config.timeout_s = 0.5;
  Cia402BusOptions options;
  options.device_watchdog_ms = kWatchdogMs;
  options.abort_connection = AbortConnection::fault;
  config.options = options;
  ActuatorBinding b;
  b.joint = "slide";
  b.device_id = kNode;
  b.ticks_per_rad = kCountsPerDeg * 180.0 / 3.141592653589793;
  Cia402JointOptions o;
  o.homing.method = 18;  // the positive limit switch, far away: a long search
  o.homing.switch_speed = static_cast<std::uint32_t>(180 * kCountsPerDeg);
  o.homing.zero_speed = static_cast<std::uint32_t>(45 * kCountsPerDeg);
  o.homing.timeout_s = 5.0;
  b.options = o;
  config.actuators.push_back(b);
  return config;
}

// The wire seen by a client of the test's own: TPDO1 positions, EMCY, SDO.
struct Wire {
  std::unique_ptr<CanFrameTransport> port;
  double furthest_deg = -1e9;
  bool heartbeat_emcy = false;
  int host_heartbeats = 0;

  void note(const can_frame& f) {
    if (f.can_id == canopen::kHeartbeatBase + 127) ++host_heartbeats;
    if (f.can_id == canopen::kTpdo1Base + kNode && f.len >= 6) {
      const auto counts = static_cast<std::int32_t>(canopen::get_le(f.data + 2, 4));
      furthest_deg = std::max(furthest_deg, counts / kCountsPerDeg);
    }
    if (f.can_id == canopen::kEmcyBase + kNode && f.len >= 2 &&
        canopen::get_le(f.data, 2) == 0x8130) {
      heartbeat_emcy = true;
    }
  }
  // Takes frames until `done` or about two wall seconds pass.
  template <typename Done>
  bool watch(Done done) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    can_frame f;
    while (!done() && std::chrono::steady_clock::now() < deadline) {
      if (port->receive(f, std::chrono::milliseconds(5))) note(f);
    }
    return done();
  }
  // Takes what is on the wire until it has been quiet a moment.
  void drain() {
    can_frame f;
    while (port->receive(f, std::chrono::milliseconds(20))) note(f);
  }
  // Expedited SDO upload of index:sub from the drive.
  std::uint32_t upload(std::uint16_t index, std::uint8_t sub) {
    can_frame request{};
    request.can_id = canopen::kRsdoBase + kNode;
    request.len = 8;
    request.data[0] = 0x40;
    canopen::put_le(request.data + 1, index, 2);
    request.data[3] = sub;
    port->send(request);
    bool answered = false;
    std::uint32_t value = 0;
    can_frame f;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (!answered && std::chrono::steady_clock::now() < deadline) {
      if (!port->receive(f, std::chrono::milliseconds(5))) continue;
      note(f);
      if (f.can_id == canopen::kTsdoBase + kNode && (f.data[0] & 0xE0) == 0x40 &&
          canopen::get_le(f.data + 1, 2) == index && f.data[3] == sub) {
        value = static_cast<std::uint32_t>(canopen::get_le(f.data + 4, 4));
        answered = true;
      }
    }
    EXPECT_TRUE(answered) << "no SDO answer from the drive";
    return value;
  }
};

TEST(Cia402HomingGuard, AHostThatDiesMidSearchLeavesTheDriveFaultedAndStopped) {
  ManualClock clock(1000 * kMs);
  const BusConfig config = slide_bus("homing_guard");
  BusConfig drive_side = config;
  SimDriveSwitches far;
  far.device_id = kNode;
  far.positive_limit_deg = 5000.0;
  drive_side.sim.switches.push_back(far);
  sim::CanSimBus sim(drive_side, clock, sim::CanSimAttach::in_process);
  sim.start();
  Wire wire{VirtualCanBus::named("homing_guard")->attach(), -1e9, false, 0};
  // Read before the host is on the bus, which would take the answer as its own.
  const double start_deg =
      static_cast<std::int32_t>(wire.upload(cia402::obj::position_actual, 0)) / kCountsPerDeg;
  auto transport = std::make_unique<MortalTransport>(open_can(config.port));
  MortalTransport& host_link = *transport;
  Cia402Bus bus(config, std::move(transport));
  bus.configure();
  bus.deactivate();

  // The simulated clock runs at about twice the wall clock while homing.
  std::atomic<bool> pacing{true};
  std::thread pacer([&] {
    while (pacing.load()) {
      if (host_link.keeping_up(clock.now())) clock.advance(kMs);
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });
  std::thread host([&] {
    try {
      bus.set_home(0, 5'000);
    } catch (const DeviceError&) {
      // what the dead host's bus makes of silence once released
    }
  });
  // The search under way: the drive's position walks up by 10 deg.
  const bool moving = wire.watch([&] { return wire.furthest_deg > start_deg + 10.0; });
  host_link.die();
  pacing = false;
  pacer.join();
  const Nanos died = clock.now();
  EXPECT_TRUE(moving) << "the search did not start";
  // Answered after every frame the host sent (the drive takes them in
  // order), all taken while the clock stands: still searching, enabled.
  const auto alive = static_cast<std::uint16_t>(wire.upload(cia402::obj::statusword, 0));
  EXPECT_EQ(cia402::decode_statusword(alive), cia402::State::operation_enabled);
  EXPECT_FALSE(wire.heartbeat_emcy);

  // Just past the consumer time since the host's last heartbeat.
  clock.set(died + (kWatchdogMs + 2) * kMs);
  EXPECT_TRUE(wire.watch([&] { return wire.heartbeat_emcy; }))
      << "no heartbeat EMCY from the drive";
  const auto sw = static_cast<std::uint16_t>(wire.upload(cia402::obj::statusword, 0));
  EXPECT_EQ(cia402::decode_statusword(sw), cia402::State::fault);
  // Stopped: a second later it is where it was.
  const auto stopped = static_cast<std::int32_t>(wire.upload(cia402::obj::position_actual, 0));
  clock.advance(1000 * kMs);
  EXPECT_EQ(static_cast<std::int32_t>(wire.upload(cia402::obj::position_actual, 0)), stopped);

  // Let the frozen host run out its homing timeout and end.
  clock.advance(10'000 * kMs);
  host_link.release();
  host.join();
  sim.stop();
}

TEST(Cia402HomingGuard, AHomingThatEndsLeavesNoGuardArmed) {
  ManualClock clock(1000 * kMs);
  const BusConfig config = slide_bus("homing_guard_clean");
  BusConfig drive_side = config;
  SimDriveSwitches limit;
  limit.device_id = kNode;
  limit.positive_limit_deg = 90.0;
  drive_side.sim.switches.push_back(limit);
  sim::CanSimBus sim(drive_side, clock, sim::CanSimAttach::in_process);
  sim.start();
  Wire wire{VirtualCanBus::named("homing_guard_clean")->attach(), -1e9, false, 0};
  auto transport = std::make_unique<MortalTransport>(open_can(config.port));
  const MortalTransport& host_link = *transport;
  Cia402Bus bus(config, std::move(transport));
  bus.configure();
  bus.deactivate();
  std::atomic<bool> pacing{true};
  std::thread pacer([&] {
    while (pacing.load()) {
      if (host_link.keeping_up(clock.now())) clock.advance(kMs);
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });
  std::int64_t reads = 0;
  try {
    reads = bus.set_home(0, 5'000);
  } catch (const DeviceError& e) {
    ADD_FAILURE() << e.what();
  }
  pacing = false;
  pacer.join();
  EXPECT_EQ(reads, 5'000);
  wire.drain();
  // Guarded while it searched; the consumer off once it was disabled, so
  // the host's silence now is no heartbeat error.
  EXPECT_GT(wire.host_heartbeats, 0);
  EXPECT_EQ(bus.sdo_read(0, cia402::obj::heartbeat_consumer, 1), 0u);
  clock.advance(1000 * kMs);
  const auto sw = static_cast<std::uint16_t>(bus.sdo_read(0, cia402::obj::statusword, 0));
  EXPECT_EQ(cia402::decode_statusword(sw), cia402::State::switch_on_disabled);
  wire.drain();
  EXPECT_FALSE(wire.heartbeat_emcy);
  sim.stop();
}

}  // namespace
}  // namespace animrt::cia402_homing_guard_test
