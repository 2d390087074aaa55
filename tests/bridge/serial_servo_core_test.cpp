// The serial-servo core's behaviour, the same for every family: each test
// runs once against a Dynamixel bus and once against a Feetech bus, over a
// scripted line whose servos answer on a schedule (each answer a fixed
// time after the one before), so the timeout is tested by what the bus
// asks the line to wait, not by how long a machine takes.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <deque>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/bridge/feetech/feetech_bus.hpp"
#include "animrt/bridge/status_book.hpp"

namespace animrt::servo_core_test {

using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;
using std::chrono::microseconds;
using std::chrono::milliseconds;

// What the master asked, as a servo reads it.
struct Request {
  enum Kind { ping, read, write, sync_read, reboot, other } kind = other;
  std::uint8_t id = 0;
  std::uint16_t address = 0;
  std::uint16_t length = 0;
  Bytes ids;  // Sync Read: who answers, in order
};

// `length` bytes of `v`, low byte first (Dynamixel; Feetech STS).
Bytes low_first(std::uint32_t v, std::size_t length) {
  Bytes out(length);
  for (std::size_t i = 0; i < length; ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * i));
  return out;
}

struct Dynamixel {
  static constexpr std::uint8_t kFault = dxl::kAlertBit;
  static constexpr std::uint16_t kPresent = dxl::xreg::present_position;
  static std::unique_ptr<ActuatorBus> make(const BusConfig& config,
                                           std::unique_ptr<ByteTransport> line) {
    return std::make_unique<DynamixelBus>(config, std::move(line));
  }
  static bool parse(const Bytes& bytes, Request& out) {
    dxl::Decoder decoder;
    decoder.feed(bytes);
    dxl::Packet p;
    if (decoder.next(p) != dxl::DecodeResult::packet) return false;
    out = Request{};
    out.id = p.id;
    const auto u16 = [&](std::size_t at) { return dxl::get_u16(p.params.data() + at); };
    switch (p.instruction) {
      case dxl::inst::ping:
        out.kind = Request::ping;
        break;
      case dxl::inst::read:
        out.kind = Request::read;
        out.address = u16(0);
        out.length = u16(2);
        break;
      case dxl::inst::write:
        out.kind = Request::write;
        out.address = u16(0);
        out.ids.assign(p.params.begin() + 2, p.params.end());  // the data written
        break;
      case dxl::inst::reboot:
        out.kind = Request::reboot;
        break;
      case dxl::inst::sync_read:
        out.kind = Request::sync_read;
        out.address = u16(0);
        out.length = u16(2);
        out.ids.assign(p.params.begin() + 4, p.params.end());
        break;
      default:
        break;
    }
    return true;
  }
  static Bytes status(std::uint8_t id, std::uint8_t error, const Bytes& data) {
    std::array<std::uint8_t, dxl::kMaxPacket> out{};
    const std::size_t n = dxl::encode_status(id, error, data, out);
    return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
  }
  // A header with an impossible id: not a packet, and behind it the search goes on.
  static Bytes junk_header() { return {0xFF, 0xFF, 0xFD, 0x00, 0xFF, 0x03, 0x00}; }
};

struct Feetech {
  static constexpr std::uint8_t kFault = ft::error_bit::overload;
  static constexpr std::uint16_t kPresent = ft::reg::present_position;
  static std::unique_ptr<ActuatorBus> make(const BusConfig& config,
                                           std::unique_ptr<ByteTransport> line) {
    return std::make_unique<FeetechBus>(config, ft::Series::sts, std::move(line));
  }
  static bool parse(const Bytes& bytes, Request& out) {
    ft::Decoder decoder;
    decoder.feed(bytes);
    ft::Packet p;
    if (decoder.next(p) != ft::DecodeResult::packet) return false;
    out = Request{};
    out.id = p.id;
    switch (p.code) {
      case ft::inst::ping:
        out.kind = Request::ping;
        break;
      case ft::inst::read:
        out.kind = Request::read;
        out.address = p.params[0];
        out.length = p.params[1];
        break;
      case ft::inst::write:
        out.kind = Request::write;
        break;
      case ft::inst::sync_read:
        out.kind = Request::sync_read;
        out.address = p.params[0];
        out.length = p.params[1];
        out.ids.assign(p.params.begin() + 2, p.params.end());
        break;
      default:
        break;
    }
    return true;
  }
  static Bytes status(std::uint8_t id, std::uint8_t error, const Bytes& data) {
    std::array<std::uint8_t, ft::kMaxPacket> out{};
    const std::size_t n = ft::encode_status(id, error, data, out);
    return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
  }
  // A header whose length is impossible (below 2).
  static Bytes junk_header() { return {0xFF, 0xFF, 0x01, 0x01}; }
};

// Servos on a line: answer k of a request arrives `gap` after answer k-1
// (the first `gap` after the request). Records the waits the master asks
// for after the last answer it was given.
template <class Family>
class ScheduledServos final : public ByteTransport {
 public:
  microseconds gap{0};
  std::set<std::uint8_t> silent;               // never answer
  std::set<std::uint8_t> damaged;              // answer with a wrong checksum
  std::map<std::uint8_t, std::uint8_t> error;  // error byte of their answers
  Bytes garbage;                               // sent before the first answer
  std::map<std::uint8_t, std::int32_t> ticks;
  std::map<std::uint16_t, std::uint32_t> registers;  // what other addresses read
  std::vector<Request> requests;                     // every packet the master sent
  microseconds waited_since_last_answer{0};
  // The answers to the next `late_requests` requests leave `late` after
  // their request (a host too busy to carry the line's bytes in time).
  int late_requests = 0;
  microseconds late{0};
  // A register added to what Present Position reads (Dynamixel's Homing
  // Offset); none if 0. A unicast write to it lands in `registers`.
  std::uint16_t offset_register = 0;

  void set_timeout(microseconds) override {}
  bool write(std::span<const std::uint8_t> bytes) override {
    Request r;
    if (!Family::parse(Bytes(bytes.begin(), bytes.end()), r)) return true;
    requests.push_back(r);
    if (r.kind == Request::write && r.id != 0xFE && offset_register != 0 &&
        r.address == offset_register && r.ids.size() == 4) {
      std::uint32_t v = 0;
      for (std::size_t i = 0; i < r.ids.size(); ++i) v |= std::uint32_t{r.ids[i]} << (8 * i);
      registers[r.address] = v;
    }
    std::vector<std::uint8_t> who;
    if (r.kind == Request::sync_read) {
      who = r.ids;
    } else if (r.id != 0xFE && r.kind != Request::other) {
      who.push_back(r.id);
    }
    auto at = Clock::now();
    if (late_requests > 0 && !who.empty()) {
      --late_requests;
      at += late;
    }
    bool first = true;
    for (std::uint8_t id : who) {
      at += gap;
      if (silent.count(id) != 0) continue;
      Bytes data;
      if (r.kind == Request::read || r.kind == Request::sync_read) {
        std::uint32_t v = registers.count(r.address) != 0 ? registers[r.address] : 0;
        if (r.address == Family::kPresent) {
          v = static_cast<std::uint32_t>(ticks[id]) +
              (offset_register != 0 ? registers[offset_register] : 0);
        }
        data = low_first(v, r.length);
      }
      Bytes a = Family::status(id, error.count(id) != 0 ? error[id] : 0, data);
      if (damaged.count(id) != 0) a.back() ^= 0x5A;
      if (first) a.insert(a.begin(), garbage.begin(), garbage.end());
      first = false;
      queue_.push_back({at, std::move(a)});
    }
    return true;
  }
  std::size_t read(std::span<std::uint8_t> buffer, microseconds wait) override {
    const auto now = Clock::now();
    if (!queue_.empty() && queue_.front().at <= now + wait) {
      std::this_thread::sleep_until(queue_.front().at);
      std::size_t n = 0;
      while (!queue_.empty() && queue_.front().at <= Clock::now() &&
             n + queue_.front().bytes.size() <= buffer.size()) {
        std::copy(queue_.front().bytes.begin(), queue_.front().bytes.end(), buffer.begin() + n);
        n += queue_.front().bytes.size();
        queue_.pop_front();
      }
      waited_since_last_answer = microseconds{0};
      return n;
    }
    waited_since_last_answer += wait;
    std::this_thread::sleep_for(wait);
    return 0;
  }
  // What has arrived; answers still on their way come later.
  void discard_input() override {
    const auto now = Clock::now();
    std::erase_if(queue_, [&](const Timed& t) { return t.at <= now; });
  }
  const char* failure() const override { return nullptr; }
  int failure_errno() const override { return 0; }
  std::uint64_t write_failures() const override { return 0; }
  const std::string& port() const override { return port_; }

 private:
  struct Timed {
    Clock::time_point at;
    Bytes bytes;
  };
  std::deque<Timed> queue_;
  std::string port_ = "scheduled";
};

template <class Family>
class SerialServoCore : public ::testing::Test {
 protected:
  static constexpr int kServos = 4;
  static constexpr double kTimeoutS = 0.030;

  void SetUp() override {
    auto owned = std::make_unique<ScheduledServos<Family>>();
    line = owned.get();
    BusConfig config;
    config.name = "core";
    config.timeout_s = kTimeoutS;
    for (int id = 1; id <= kServos; ++id) {
      ActuatorBinding b;
      b.joint = "j" + std::to_string(id);
      b.device_id = id;
      b.zero_ticks = 2048;
      config.actuators.push_back(b);
      line->ticks[static_cast<std::uint8_t>(id)] = 2048 + 10 * id;
    }
    bus = Family::make(config, std::move(owned));
    bus->configure();
    q.assign(kServos, 0.0);
    bus->read(q);  // hands out what configure() read
  }

  const DeviceStatus& dev(int id) const { return bus->devices()[static_cast<std::size_t>(id - 1)]; }

  ScheduledServos<Family>* line = nullptr;
  std::unique_ptr<ActuatorBus> bus;
  std::vector<double> q;
};

using Families = ::testing::Types<Dynamixel, Feetech>;
TYPED_TEST_SUITE(SerialServoCore, Families);

TYPED_TEST(SerialServoCore, ASlowButSteadySyncReadIsNoTimeout) {
  // Every answer comes within one timeout of the one before, all of them
  // together take more than two timeouts: the timeout is per answer.
  this->line->gap = std::chrono::duration_cast<microseconds>(
      std::chrono::duration<double>(this->kTimeoutS * 0.6));
  for (int id = 1; id <= this->kServos; ++id)
    this->line->ticks[static_cast<std::uint8_t>(id)] += 100;
  this->bus->read(this->q);
  for (int id = 1; id <= this->kServos; ++id) {
    EXPECT_EQ(this->dev(id).timeouts, 0u) << "id " << id;
    EXPECT_EQ(this->dev(id).health, DeviceHealth::ok) << "id " << id;
    EXPECT_NEAR(this->q[static_cast<std::size_t>(id - 1)],
                (10.0 * id + 100) * 2 * std::numbers::pi / 4096, 1e-9);
  }
}

TYPED_TEST(SerialServoCore, AMissingAnswerTimesOutAfterOneTimeout) {
  this->line->gap = milliseconds(5);
  this->line->silent = {4};
  this->bus->read(this->q);
  for (int id = 1; id <= 3; ++id) EXPECT_EQ(this->dev(id).health, DeviceHealth::ok);
  EXPECT_EQ(this->dev(4).timeouts, 1u);
  EXPECT_EQ(this->dev(4).health, DeviceHealth::timeout);
  // After the last answer the bus waited one timeout for the next, no more
  // (however many answers were still owed).
  const auto timeout = microseconds(static_cast<long>(this->kTimeoutS * 1e6));
  EXPECT_LE(this->line->waited_since_last_answer, timeout + microseconds(5));
  EXPECT_GT(this->line->waited_since_last_answer, microseconds(0));
}

TYPED_TEST(SerialServoCore, TheStatusBookCountsAndFollowsEveryTransition) {
  const auto before =
      std::vector<DeviceStatus>(this->bus->devices().begin(), this->bus->devices().end());
  // Servo 2 silent: a timeout, the others ok.
  this->line->silent = {2};
  this->bus->read(this->q);
  EXPECT_EQ(this->dev(2).health, DeviceHealth::timeout);
  EXPECT_EQ(this->dev(2).timeouts, before[1].timeouts + 1);
  EXPECT_EQ(this->dev(1).health, DeviceHealth::ok);
  // Back: ok again, the count stays.
  this->line->silent.clear();
  this->bus->read(this->q);
  EXPECT_EQ(this->dev(2).health, DeviceHealth::ok);
  EXPECT_EQ(this->dev(2).timeouts, before[1].timeouts + 1);
  // A damaged answer: a checksum error, and nothing taken from it.
  const double q1 = this->q[0];
  this->line->ticks[1] += 500;
  this->line->damaged = {1};
  this->bus->read(this->q);
  EXPECT_EQ(this->dev(1).health, DeviceHealth::protocol_error);
  EXPECT_EQ(this->dev(1).crc_errors, before[0].crc_errors + 1);
  EXPECT_EQ(this->q[0], q1);
  EXPECT_EQ(this->dev(2).health, DeviceHealth::ok);
  this->line->damaged.clear();
  // A servo that reports a fault: counted, its health says so, its position is taken.
  this->line->error[3] = TypeParam::kFault;
  this->bus->read(this->q);
  EXPECT_EQ(this->dev(3).health, DeviceHealth::hardware_error);
  EXPECT_EQ(this->dev(3).hardware_errors, before[2].hardware_errors + 1);
  EXPECT_EQ(this->dev(3).last_error_byte, TypeParam::kFault);
  EXPECT_NEAR(this->q[2], 30.0 * 2 * std::numbers::pi / 4096, 1e-9);
  EXPECT_NEAR(this->q[0], 510.0 * 2 * std::numbers::pi / 4096, 1e-9);
  this->line->error.clear();
  this->bus->read(this->q);
  EXPECT_EQ(this->dev(3).health, DeviceHealth::ok);
  // Every read asked every servo once.
  for (int id = 1; id <= this->kServos; ++id) {
    EXPECT_GE(this->dev(id).transactions,
              before[static_cast<std::size_t>(id - 1)].transactions + 5);
  }
}

TYPED_TEST(SerialServoCore, GarbageBeforeAndBetweenAnswersIsSkipped) {
  // Idle-line bytes, half a header, and a header with an impossible
  // length before the answers: the decoder finds the real header behind
  // them, and the servos' answers are all taken.
  Bytes junk = {0x00, 0x13, 0xFF, 0x42, 0xFF, 0xFF, 0xFF};
  const Bytes bad = TypeParam::junk_header();
  junk.insert(junk.end(), bad.begin(), bad.end());
  this->line->garbage = junk;
  for (int id = 1; id <= this->kServos; ++id) this->line->ticks[static_cast<std::uint8_t>(id)] -= 5;
  this->bus->read(this->q);
  for (int id = 1; id <= this->kServos; ++id) {
    EXPECT_EQ(this->dev(id).timeouts, 0u) << "id " << id;
    EXPECT_NEAR(this->q[static_cast<std::size_t>(id - 1)],
                (10.0 * id - 5) * 2 * std::numbers::pi / 4096, 1e-9);
  }
  for (int id = 2; id <= this->kServos; ++id) EXPECT_EQ(this->dev(id).health, DeviceHealth::ok);
  // The impossible header was counted against the servo whose answer was due.
  EXPECT_EQ(this->dev(1).protocol_errors, 1u);
}

TEST(DynamixelBusWatchdog, IsRearmedWhenNothingValidWasHeardForHalfItsTime) {
  // The host keeps sending every cycle, but no valid answer comes back (what
  // it sent sat in a buffer: the servos heard nothing either, and their
  // guard may have fired). After half the guard's time the bus clears and
  // re-arms it by broadcast, and stops once answers come again.
  auto owned = std::make_unique<ScheduledServos<Dynamixel>>();
  ScheduledServos<Dynamixel>& line = *owned;
  // 1 s: a test thread held off the CPU for a while in the answered phases
  // must not look like a silence of half of it.
  constexpr std::uint8_t kUnits = 50;
  BusConfig config;
  config.name = "guarded";
  config.timeout_s = 0.002;
  dxl::BusOptions options;
  options.bus_watchdog = kUnits;
  config.options = options;
  for (std::uint8_t id : {1, 2}) {
    ActuatorBinding b;
    b.joint = "j" + std::to_string(id);
    b.device_id = id;
    config.actuators.push_back(b);
    line.ticks[id] = 2048;
  }
  line.registers[dxl::xreg::bus_watchdog] = kUnits;  // reads back as armed
  DynamixelBus bus(config, std::move(owned));
  bus.configure();
  bus.activate();
  bus.arm_device_guard();
  const auto rearm_broadcasts = [&] {
    int n = 0;
    for (const Request& r : line.requests) {
      n += r.kind == Request::write && r.id == dxl::kBroadcastId &&
           r.address == dxl::xreg::bus_watchdog && r.ids == Bytes{kUnits};
    }
    return n;
  };
  const int armed = rearm_broadcasts();
  std::vector<double> q(2, 0.0);
  const auto cycles_for = [&](milliseconds span) {
    const auto end = Clock::now() + span;
    while (Clock::now() < end) {
      bus.read(q);
      bus.write(q);
      std::this_thread::sleep_for(milliseconds(5));
    }
  };
  // Answers every cycle for longer than half the guard: nothing to re-arm.
  cycles_for(milliseconds(700));
  EXPECT_EQ(bus.watchdog_rearms(), 0u);
  // Sent every cycle, never answered, for longer than half the guard.
  line.silent = {1, 2};
  cycles_for(milliseconds(700));
  EXPECT_GE(bus.watchdog_rearms(), 1u);
  EXPECT_EQ(rearm_broadcasts() - armed, static_cast<int>(bus.watchdog_rearms()));
  // Heard again: no more re-arming.
  line.silent.clear();
  bus.read(q);
  const std::uint64_t rearms = bus.watchdog_rearms();
  cycles_for(milliseconds(300));
  EXPECT_EQ(bus.watchdog_rearms(), rearms);
  bus.deactivate();
}

TEST(DynamixelBusLateAnswers, ARetriedReadsLaterAnswerIsNotTakenForTheNextRead) {
  // Every answer leaves 2 timeouts after its request: each try times out
  // and the answer to the first comes during the second (half way through
  // its wait of 2 timeouts), whose own answer is still on its way when the
  // next read is sent. set_home reads Present
  // Position, then Homing Offset (both 4 bytes from the same id): taken for
  // the Homing Offset, that later answer would make the home the shaft's
  // 0 and the servo read 2048 + 2867 after the Reboot.
  auto owned = std::make_unique<ScheduledServos<Dynamixel>>();
  ScheduledServos<Dynamixel>& line = *owned;
  BusConfig config;
  config.name = "legs";
  config.timeout_s = 0.040;
  ActuatorBinding b;
  b.joint = "knee";
  b.device_id = 1;
  b.ticks_per_rad = 16384 / (2 * std::numbers::pi);  // geared 4:1
  b.zero_ticks = 2048;
  dxl::DeviceOptions options;
  options.multi_turn = true;
  b.options = options;
  config.actuators.push_back(b);
  line.ticks[1] = 2867;  // within the shaft's first turn: a Reboot keeps the count
  line.registers[dxl::xreg::operating_mode] = dxl::kExtendedPositionMode;
  line.offset_register = dxl::xreg::homing_offset;
  DynamixelBus bus(config, std::move(owned));
  bus.configure();
  // Torque off, Present Position, Homing Offset: each tried twice.
  line.late_requests = 6;
  line.late = microseconds(80'000);
  EXPECT_EQ(bus.set_home(0, 2048), 2048);
  EXPECT_EQ(static_cast<std::int32_t>(line.registers[dxl::xreg::homing_offset]), 2048 - 2867);
}

TEST(StatusBook, NamesTheBusAndItsDevices) {
  BusConfig config;
  config.name = "legs";
  ActuatorBinding b;
  b.joint = "knee";
  b.device_id = 7;
  config.actuators.push_back(b);
  StatusBook book(config, "/dev/ttyUSB0", "node");
  EXPECT_EQ(book.prefix(), "bus legs (/dev/ttyUSB0): ");
  EXPECT_EQ(book.describe(0), "node 7 (knee)");
  book.asked(0);
  book.timed_out(0);
  book.garbled(0, true);
  book.hardware_fault(0, 0x20);
  EXPECT_EQ(book[0].transactions, 1u);
  EXPECT_EQ(book[0].timeouts, 1u);
  EXPECT_EQ(book[0].crc_errors, 1u);
  EXPECT_EQ(book[0].health, DeviceHealth::hardware_error);
  EXPECT_EQ(book[0].hardware_error_status, 0x20);
  book.reset();
  EXPECT_EQ(book[0].transactions, 0u);
  EXPECT_EQ(book[0].device_id, 7);
  EXPECT_EQ(book[0].health, DeviceHealth::ok);
}

}  // namespace animrt::servo_core_test
