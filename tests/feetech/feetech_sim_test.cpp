// The simulated Feetech servo board over a real pseudo-terminal: it answers
// the protocol manual's example packets with the manual's status packets,
// and drops a packet with a bad checksum without answering, as a servo does.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/sim/feetech/feetech_sim_bus.hpp"
#include "support/eventually.hpp"

namespace animrt {
namespace {

using Bytes = std::vector<std::uint8_t>;
using namespace std::chrono_literals;

BusConfig servos(std::initializer_list<int> ids, const char* protocol = "feetech_sts") {
  BusConfig config;
  config.name = "arm";
  config.protocol = protocol;
  for (int id : ids) {
    ActuatorBinding b;
    b.joint = "j" + std::to_string(id);
    b.device_id = id;
    b.ticks_per_rad = 4096.0 / (2.0 * 3.14159265358979323846);
    b.zero_ticks = 2048;
    config.actuators.push_back(b);
  }
  return config;
}

// Collects what comes back until `expect` bytes arrived or `wait` passed.
Bytes collect(ByteTransport& line, std::size_t expect, std::chrono::milliseconds wait) {
  Bytes got;
  std::array<std::uint8_t, 256> buf{};
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (got.size() < expect) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) break;
    const std::size_t n =
        line.read(buf, std::chrono::ceil<std::chrono::microseconds>(deadline - now));
    got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  }
  return got;
}

// The test's end of the simulated servos' line, counting the bytes it sent:
// once the servos have read as many, they have answered every request.
struct Wire {
  ByteTransport& port;
  const sim::FeetechSimBus& sim;
  std::uint64_t sent = 0;
};

void send(Wire& w, const Bytes& request) {
  w.port.discard_input();
  w.port.write(request);
  w.sent += request.size();
}

// Until the servos have read and handled every byte sent (a loaded machine
// may hold their thread off the CPU for a while).
void settle(const Wire& w) {
  ASSERT_TRUE(test::eventually([&] { return w.sim.stats().received_bytes == w.sent; }));
}

// Sends `request` and collects its answer of `expect` bytes.
Bytes exchange(Wire& w, const Bytes& request, std::size_t expect) {
  send(w, request);
  return collect(w.port, expect, 5s);
}

// Sends `request`, which no servo answers, and returns what came within
// 50 ms after the servos took it; no answer may have been sent for it.
Bytes unanswered(Wire& w, const Bytes& request) {
  settle(w);
  const std::uint64_t answers = w.sim.stats().answers;
  send(w, request);
  settle(w);
  EXPECT_EQ(w.sim.stats().answers, answers);
  return collect(w.port, 1, 50ms);
}

const Bytes kNoAnswer;
const Bytes kAck1 = {0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC};

TEST(FeetechSimBoard, AnswersTheManualsExamplePackets) {
  ManualClock clock{0};
  sim::FeetechSimBus sim(servos({1, 2}), ft::Series::sts, clock);
  sim.start();
  auto line = open_serial(sim.endpoint(), 1'000'000);
  Wire wire{*line, sim};

  // Example 1: Ping.
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB}, 6), kAck1);
  // Example 4: position 2048, time 0, speed 1000 to ID 1.
  EXPECT_EQ(
      exchange(wire, {0xFF, 0xFF, 0x01, 0x09, 0x03, 0x2A, 0x00, 0x08, 0x00, 0x00, 0xE8, 0x03, 0xD5},
               6),
      kAck1);
  EXPECT_EQ(sim.device_last_goal(1), 2048);
  // Example 5: the same by Reg Write (answered), then Example 6: Action
  // (broadcast, not answered).
  EXPECT_EQ(
      exchange(wire, {0xFF, 0xFF, 0x01, 0x09, 0x04, 0x2A, 0x00, 0x08, 0x00, 0x00, 0xE8, 0x03, 0xD4},
               6),
      kAck1);
  EXPECT_EQ(unanswered(wire, {0xFF, 0xFF, 0xFE, 0x02, 0x05, 0xFA}), kNoAnswer);
  // Torque on (computed packets: write 1 to address 40).
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x01, 0x04, 0x03, 0x28, 0x01, 0xCE}, 6), kAck1);
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x02, 0x04, 0x03, 0x28, 0x01, 0xCD}, 6),
            (Bytes{0xFF, 0xFF, 0x02, 0x02, 0x00, 0xFB}));
  // Example 7: Sync Write of 2048 to IDs 1..4 (3 and 4 are absent), not answered.
  EXPECT_EQ(
      unanswered(wire, {0xFF, 0xFF, 0xFE, 0x20, 0x83, 0x2A, 0x06, 0x01, 0x00, 0x08, 0x00, 0x00,
                        0xE8, 0x03, 0x02, 0x00, 0x08, 0x00, 0x00, 0xE8, 0x03, 0x03, 0x00, 0x08,
                        0x00, 0x00, 0xE8, 0x03, 0x04, 0x00, 0x08, 0x00, 0x00, 0xE8, 0x03, 0x58}),
      kNoAnswer);
  EXPECT_EQ(sim.device_last_goal(2), 2048);
  // ID 2 to 2047 (computed packet), so the servos stand where Example 8 has them.
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x02, 0x05, 0x03, 0x2A, 0xFF, 0x07, 0xC5}, 6),
            (Bytes{0xFF, 0xFF, 0x02, 0x02, 0x00, 0xFB}));
  clock.advance(5'000'000'000);  // long enough to settle
  // Example 8: Sync Read of 8 bytes at 0x38 from IDs 1 and 2: the manual's
  // two status packets, byte for byte (position, speed 0, load 0, 12.1 V, 30 C).
  const Bytes id1 = {0xFF, 0xFF, 0x01, 0x0A, 0x00, 0x00, 0x08,
                     0x00, 0x00, 0x00, 0x00, 0x79, 0x1E, 0x55};
  const Bytes id2 = {0xFF, 0xFF, 0x02, 0x0A, 0x00, 0xFF, 0x07,
                     0x00, 0x00, 0x00, 0x00, 0x77, 0x23, 0x53};
  Bytes both = id1;
  both.insert(both.end(), id2.begin(), id2.end());
  // The manual's ID 2 packet reports 11.9 V and 35 C: the board models one
  // voltage and temperature, so only ID 1's answer is compared whole.
  const Bytes answer =
      exchange(wire, {0xFF, 0xFF, 0xFE, 0x06, 0x82, 0x38, 0x08, 0x01, 0x02, 0x36}, 28);
  ASSERT_EQ(answer.size(), 28u);
  EXPECT_EQ(Bytes(answer.begin(), answer.begin() + 14), id1);
  EXPECT_EQ(Bytes(answer.begin() + 14, answer.begin() + 21), Bytes(id2.begin(), id2.begin() + 7));
  // Example 2: Read of the present position (the answer computed: 2048).
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE}, 8),
            (Bytes{0xFF, 0xFF, 0x01, 0x04, 0x00, 0x00, 0x08, 0xF2}));
  // A bad checksum: silence, as from a servo.
  EXPECT_EQ(unanswered(wire, {0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFA}), kNoAnswer);
  EXPECT_EQ(sim.stats().bad_checksums, 1u);
}

TEST(FeetechSimBoard, BroadcastWriteOfTheIdAnswersNothingAndRenamesTheServo) {
  ManualClock clock{0};
  sim::FeetechSimBus sim(servos({7}), ft::Series::sts, clock);
  sim.start();
  auto line = open_serial(sim.endpoint(), 1'000'000);
  Wire wire{*line, sim};
  // Example 3: any id -> 1, broadcast: no answer.
  EXPECT_EQ(unanswered(wire, {0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x05, 0x01, 0xF4}), kNoAnswer);
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB}, 6), kAck1);
}

TEST(FeetechSimBoard, ScsServosAnswerHighByteFirstAndIgnoreSyncRead) {
  ManualClock clock{0};
  BusConfig config = servos({1}, "feetech_scs");
  config.actuators[0].ticks_per_rad = ft::kScsStepsPerRev / (2.0 * 3.14159265358979323846);
  config.actuators[0].zero_ticks = 512;
  sim::FeetechSimBus sim(config, ft::Series::scs, clock);
  sim.start();
  auto line = open_serial(sim.endpoint(), 1'000'000);
  Wire wire{*line, sim};
  // Goal 0x0300 = 768, high byte first, then torque on.
  std::array<std::uint8_t, ft::kMaxPacket> tx{};
  const std::uint8_t goal[2] = {0x03, 0x00};
  std::size_t n = ft::encode_write(1, ft::reg::goal_position, goal, tx);
  EXPECT_EQ(exchange(wire, Bytes(tx.begin(), tx.begin() + n), 6), kAck1);
  EXPECT_EQ(sim.device_last_goal(1), 768);
  const std::uint8_t on = 1;
  n = ft::encode_write(1, ft::reg::torque_enable, {&on, 1}, tx);
  EXPECT_EQ(exchange(wire, Bytes(tx.begin(), tx.begin() + n), 6), kAck1);
  clock.advance(5'000'000'000);
  // The manual's Read packet; the answer carries 768 as 03 00.
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x02, 0xBE}, 8),
            (Bytes{0xFF, 0xFF, 0x01, 0x04, 0x00, 0x03, 0x00, 0xF7}));
  EXPECT_EQ(unanswered(wire, {0xFF, 0xFF, 0xFE, 0x06, 0x82, 0x38, 0x08, 0x01, 0x02, 0x36}),
            kNoAnswer);
}

TEST(FeetechSimBoard, FaultBitsShowInTheErrorByteAndCutTorque) {
  ManualClock clock{0};
  sim::FeetechSimBus sim(servos({1}), ft::Series::sts, clock);
  sim.start();
  auto line = open_serial(sim.endpoint(), 1'000'000);
  Wire wire{*line, sim};
  sim.set_device_hardware_error(1, ft::error_bit::overload);
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB}, 6),
            (Bytes{0xFF, 0xFF, 0x01, 0x02, 0x20, 0xDC}));
  // Torque on is refused while the overload is latched: reads back 0.
  exchange(wire, {0xFF, 0xFF, 0x01, 0x04, 0x03, 0x28, 0x01, 0xCE}, 6);
  EXPECT_EQ(exchange(wire, {0xFF, 0xFF, 0x01, 0x04, 0x02, 0x28, 0x01, 0xCF}, 7),
            (Bytes{0xFF, 0xFF, 0x01, 0x03, 0x20, 0x00, 0xDB}));
}

}  // namespace
}  // namespace animrt
