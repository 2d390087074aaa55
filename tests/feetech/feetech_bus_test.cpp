// FeetechBus against a scripted line: what a half-duplex adapter and a
// misbehaving servo put on the wire (the echo of our own packets, damaged
// checksums, cut-off answers, answers from the wrong id) is counted per
// servo and never taken for an answer.

#include "animrt/bridge/feetech/feetech_bus.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt {
namespace {

using Bytes = std::vector<std::uint8_t>;

// A line whose far end is a function: each packet written may be echoed and
// answered with whatever bytes the script returns.
class ScriptedLine final : public ByteTransport {
 public:
  std::function<Bytes(const Bytes&)> answer;
  bool echo = false;
  int stalls = 0;  // reads that come back empty only after their timeout

  void set_timeout(std::chrono::microseconds) override {}
  bool write(std::span<const std::uint8_t> bytes) override {
    const Bytes packet(bytes.begin(), bytes.end());
    written.push_back(packet);
    if (echo) pending_.insert(pending_.end(), packet.begin(), packet.end());
    if (answer) {
      const Bytes a = answer(packet);
      pending_.insert(pending_.end(), a.begin(), a.end());
    }
    return true;
  }
  std::size_t read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout) override {
    if (stalls > 0 && timeout.count() > 0) {
      // As if this thread was not scheduled until the wait was over: the
      // answer is queued, but the reader saw nothing in time.
      --stalls;
      std::this_thread::sleep_for(timeout + std::chrono::milliseconds(1));
      return 0;
    }
    const std::size_t n = std::min(buffer.size(), pending_.size());
    std::copy_n(pending_.begin(), n, buffer.begin());
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
  }
  void discard_input() override {}  // answers arrive only after a write here
  const char* failure() const override { return nullptr; }
  int failure_errno() const override { return 0; }
  std::uint64_t write_failures() const override { return 0; }
  const std::string& port() const override { return port_; }

  std::vector<Bytes> written;

 private:
  std::deque<std::uint8_t> pending_;
  std::string port_ = "scripted";
};

Bytes status(std::uint8_t id, std::uint8_t error, Bytes data) {
  std::array<std::uint8_t, ft::kMaxPacket> out{};
  const std::size_t n = ft::encode_status(id, error, data, out);
  return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
}

// Servos 1 and 2 at 2048 + id, answering Ping and Read of the position.
Bytes healthy(const Bytes& packet) {
  const std::uint8_t id = packet[2];
  const std::uint8_t code = packet[4];
  if (code == ft::inst::ping || code == ft::inst::write) return status(id, 0, {});
  if (code == ft::inst::read) {
    return status(id, 0, {static_cast<std::uint8_t>(id), 0x08});
  }
  if (code == ft::inst::sync_read) {
    Bytes out;
    for (std::size_t i = 7; i + 1 < packet.size(); ++i) {
      const Bytes one = status(packet[i], 0, {packet[i], 0x08});
      out.insert(out.end(), one.begin(), one.end());
    }
    return out;
  }
  return {};
}

struct Rig {
  explicit Rig(ft::Series series = ft::Series::sts) {
    auto owned = std::make_unique<ScriptedLine>();
    line = owned.get();
    line->answer = healthy;
    BusConfig config;
    config.name = "arm";
    config.timeout_s = 0.001;
    for (int id : {1, 2}) {
      ActuatorBinding b;
      b.joint = "j" + std::to_string(id);
      b.device_id = id;
      b.zero_ticks = 2048;
      config.actuators.push_back(b);
    }
    bus = std::make_unique<FeetechBus>(config, series, std::move(owned));
  }
  ScriptedLine* line;
  std::unique_ptr<FeetechBus> bus;
};

TEST(FeetechBus, TheAdaptersEchoIsNoAnswer) {
  Rig rig;
  rig.line->echo = true;
  rig.bus->configure();
  std::vector<double> q(2, 0.0);
  rig.bus->read(q);
  rig.bus->write(q);  // the echo of this Sync Write comes before the next answers
  rig.bus->read(q);
  for (const DeviceStatus& st : rig.bus->devices()) {
    EXPECT_EQ(st.protocol_errors, 0u);
    EXPECT_EQ(st.timeouts, 0u);
    EXPECT_EQ(st.health, DeviceHealth::ok);
  }
  EXPECT_NEAR(q[0], 0.0 + (2049 - 2048) * 2 * 3.14159265358979 / 4096, 1e-9);  // 0x0801
  EXPECT_NEAR(q[1], (2050 - 2048) * 2 * 3.14159265358979 / 4096, 1e-9);
}

TEST(FeetechBus, ConfigureWaitsForAServoThatIsStillBooting) {
  // Servo 2 ignores more pings than one round's retries (as one powered
  // together with the adapter does while it boots); the next round finds
  // it, and servo 1, which answered at once, is not asked again.
  Rig rig;
  int ignored = 0;
  rig.line->answer = [&](const Bytes& packet) {
    if (packet[2] == 2 && packet[4] == ft::inst::ping && ignored < FeetechBus::kTries + 1) {
      ++ignored;
      return Bytes{};
    }
    return healthy(packet);
  };
  rig.bus->configure();
  int pings_to_1 = 0, pings_to_2 = 0;
  for (const Bytes& p : rig.line->written) {
    if (p[4] != ft::inst::ping) continue;
    pings_to_1 += p[2] == 1 ? 1 : 0;
    pings_to_2 += p[2] == 2 ? 1 : 0;
  }
  EXPECT_EQ(pings_to_1, 1);
  EXPECT_EQ(pings_to_2, FeetechBus::kTries + 2);
  std::vector<double> q(2, 0.0);
  rig.bus->read(q);
  EXPECT_NEAR(q[1], (2050 - 2048) * 2 * 3.14159265358979 / 4096, 1e-9);
}

TEST(FeetechBus, DamagedTruncatedAndStrayAnswersAreCountedPerServo) {
  Rig rig;
  rig.bus->configure();
  std::vector<double> q(2, 0.0);
  rig.bus->read(q);
  const std::vector<double> before = q;
  // Servo 1's answer with a bad checksum, servo 2's cut short.
  rig.line->answer = [](const Bytes&) {
    Bytes a = status(1, 0, {0x00, 0x09});
    a.back() ^= 0xFF;
    const Bytes b = status(2, 0, {0x00, 0x09});
    a.insert(a.end(), b.begin(), b.end() - 2);
    return a;
  };
  rig.bus->read(q);
  EXPECT_EQ(rig.bus->devices()[0].crc_errors, 1u);
  EXPECT_EQ(rig.bus->devices()[0].health, DeviceHealth::protocol_error);
  EXPECT_EQ(rig.bus->devices()[1].protocol_errors, 1u);
  EXPECT_EQ(rig.bus->devices()[1].timeouts, 0u);
  EXPECT_EQ(q, before);  // nothing made up
  // An answer from an id nobody asked, then nothing: a protocol error, then
  // timeouts.
  rig.line->answer = [](const Bytes&) { return status(9, 0, {0x00, 0x08}); };
  rig.bus->read(q);
  EXPECT_EQ(rig.bus->devices()[0].protocol_errors, 1u);
  EXPECT_EQ(rig.bus->devices()[1].timeouts, 1u);
  // A 1-byte answer to a 2-byte read from the right id: not taken.
  rig.line->answer = [](const Bytes&) {
    Bytes a = status(1, 0, {0x05});
    const Bytes b = status(2, 0, {0x00, 0x08});
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  rig.bus->read(q);
  EXPECT_EQ(rig.bus->devices()[0].protocol_errors, 2u);
  EXPECT_EQ(q[0], before[0]);
  EXPECT_NEAR(q[1], 0.0, 1e-12);  // servo 2 at 0x0800 = 2048 = 0 rad
  EXPECT_EQ(rig.bus->devices()[1].health, DeviceHealth::ok);
}

TEST(FeetechBus, AnAnswerQueuedBeforeALateWakeUpIsNoTimeout) {
  Rig rig;
  rig.bus->configure();
  std::vector<double> q(2, 0.0);
  rig.bus->read(q);
  rig.line->stalls = 1;
  rig.bus->read(q);
  for (const DeviceStatus& st : rig.bus->devices()) {
    EXPECT_EQ(st.timeouts, 0u);
    EXPECT_EQ(st.health, DeviceHealth::ok);
  }
  // Past the deadline the bus looks once more, and no longer: nothing queued
  // then is a timeout.
  rig.line->stalls = 1;
  rig.line->answer = nullptr;
  rig.bus->read(q);
  EXPECT_EQ(rig.bus->devices()[0].timeouts, 1u);
  EXPECT_EQ(rig.bus->devices()[1].timeouts, 1u);
}

TEST(FeetechBus, ScsReadsOneServoAtATimeHighByteFirst) {
  Rig rig(ft::Series::scs);
  rig.bus->configure();
  rig.line->written.clear();
  std::vector<double> q(2, 0.0);
  rig.bus->read(q);  // configure's values, then one Read per servo
  rig.bus->read(q);
  ASSERT_EQ(rig.line->written.size(), 4u);
  for (const Bytes& p : rig.line->written) EXPECT_EQ(p[4], ft::inst::read);
  // healthy() answers {id, 0x08}: high byte first that is 0x0108 / 0x0208.
  EXPECT_NEAR(q[0], (0x0108 - 2048) * 2 * 3.14159265358979 / 4096, 1e-9);
  EXPECT_NEAR(q[1], (0x0208 - 2048) * 2 * 3.14159265358979 / 4096, 1e-9);
}

TEST(FeetechBus, GoalsAreClampedAndNanHoldsTheLastGoal) {
  Rig rig(ft::Series::scs);
  rig.bus->configure();
  rig.line->written.clear();
  // SCS positions are 0..1023: a goal beyond is clamped, never wrapped.
  rig.bus->write(std::vector<double>{100.0, -100.0});
  ASSERT_EQ(rig.line->written.size(), 1u);
  const Bytes& p = rig.line->written[0];
  ASSERT_EQ(p.size(), 8u + 6u);
  EXPECT_EQ(p[4], ft::inst::sync_write);
  EXPECT_EQ(ft::get_u16(ft::Series::scs, &p[8]), 1023);
  EXPECT_EQ(ft::get_u16(ft::Series::scs, &p[11]), 0);
  rig.bus->write(std::vector<double>{std::nan(""), 0.0});
  EXPECT_EQ(ft::get_u16(ft::Series::scs, &rig.line->written[1][8]), 1023);
}

TEST(FeetechBus, RefusesBadConfigs) {
  BusConfig config;
  config.name = "arm";
  ActuatorBinding b;
  b.joint = "j";
  b.device_id = 254;
  config.actuators.push_back(b);
  EXPECT_THROW((void)FeetechBus(config, ft::Series::sts, std::make_unique<ScriptedLine>()),
               DeviceError);
  config.actuators[0].device_id = 3;
  config.actuators.push_back(config.actuators[0]);
  EXPECT_THROW((void)FeetechBus(config, ft::Series::sts, std::make_unique<ScriptedLine>()),
               DeviceError);
  config.actuators.resize(FeetechBus::kMaxDevices + 1);
  for (std::size_t i = 0; i < config.actuators.size(); ++i) {
    config.actuators[i].device_id = static_cast<int>(i);
  }
  EXPECT_THROW((void)FeetechBus(config, ft::Series::sts, std::make_unique<ScriptedLine>()),
               DeviceError);
}

}  // namespace
}  // namespace animrt
