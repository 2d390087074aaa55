// The line as real serial servos see it: a servo hears only packets sent at
// its own baud rate (the one the host set on the pseudo-terminal), answers a
// change of its baud rate at the old one and then only at the new one, and
// two servos sharing an ID answer at once, so their packets collide.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"
#include "animrt/bridge/feetech/link_codec.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/dynamixel_sim_bus.hpp"
#include "animrt/sim/feetech/feetech_sim_bus.hpp"
#include "animrt/sim/serial_line.hpp"
#include "sim/pty_client.hpp"

namespace animrt {
namespace {

namespace xreg = dxl::xreg;
using test::Bytes;

BusConfig dynamixel_bus(std::vector<int> ids, int baud) {
  BusConfig config;
  config.name = "legs";
  config.protocol = "dynamixel2";
  config.baud = baud;
  config.timeout_s = 0.05;
  for (int id : ids) {
    ActuatorBinding b;
    b.joint = "joint" + std::to_string(id);
    b.joint_index = static_cast<int>(config.actuators.size());
    b.device_id = id;
    config.actuators.push_back(b);
  }
  return config;
}

constexpr auto kQuiet = std::chrono::milliseconds(150);

// Sends `bytes`, a packet no servo should hear, and checks that none
// answered it.
template <class Sim>
void send_unheard(test::PtyClient& line, const Sim& sim, const Bytes& bytes) {
  ASSERT_TRUE(test::handled_all(line, sim));
  const std::uint64_t answers = sim.stats().answers;
  line.send(bytes);
  ASSERT_TRUE(test::handled_all(line, sim));
  EXPECT_EQ(sim.stats().answers, answers);
}

// Sends `bytes` and reads what the servos answer once they have sent it.
template <class Sim>
Bytes answers_to(test::PtyClient& line, const Sim& sim, const Bytes& bytes) {
  line.send(bytes);
  EXPECT_TRUE(test::handled_all(line, sim));
  return line.read_raw(64, kQuiet);
}

TEST(ServoLine, ServoHearsOnlyItsOwnBaud) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3}, 1'000'000), clock);
  sim.start();
  test::PtyClient line(sim.endpoint(), 57600);
  send_unheard(line, sim, test::ping(3));
  EXPECT_TRUE(line.silent(kQuiet));
  line.set_baud(1'000'000);
  EXPECT_EQ(line.transact(test::ping(3)).id, 3);
}

TEST(ServoLine, NewBaudRateTakesEffectAfterTheAnswer) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3}, 1'000'000), clock);
  sim.start();
  test::PtyClient line(sim.endpoint(), 1'000'000);
  // Baud Rate 1 (57600): the status packet still comes at 1 Mbaud.
  EXPECT_EQ(line.transact(test::write(3, xreg::baud_rate, {1})).error, 0);
  send_unheard(line, sim, test::ping(3));
  EXPECT_TRUE(line.silent(kQuiet));
  line.set_baud(57600);
  EXPECT_EQ(line.transact(test::ping(3)).id, 3);
  EXPECT_EQ(sim.servo_readout(3).baud, 57600);
}

TEST(ServoLine, RuntimeTransportSetsTheBaudTheServosHear) {
  ManualClock clock{0};
  BusConfig config = dynamixel_bus({1}, 57600);
  sim::DynamixelSimBus sim(config, clock, nullptr, ServoStartup{true, nullptr});  // ID 1, 57600
  sim.start();
  {
    auto transport = open_serial(sim.endpoint(), 115200);
    const int fd = ::open(sim.endpoint().c_str(), O_RDWR | O_NOCTTY);
    EXPECT_EQ(sim::line::line_baud(fd), 115200);
    ::close(fd);
  }
  DynamixelBus wrong(dynamixel_bus({1}, 1'000'000), open_serial(sim.endpoint(), 1'000'000));
  EXPECT_THROW(wrong.configure(), DeviceError);
  DynamixelBus right(config, open_serial(sim.endpoint(), 57600));
  EXPECT_NO_THROW(right.configure());
}

TEST(ServoLine, ServosSharingAnIdCollide) {
  ManualClock clock{0};
  sim::DynamixelSimBus sim(dynamixel_bus({3, 4, 5}, 57600), clock, nullptr,
                           ServoStartup{true, nullptr});
  sim.start();
  test::PtyClient line(sim.endpoint(), 57600);
  EXPECT_EQ(line.transact(test::ping(1)).id, 1);  // one new servo: a clean answer
  sim.set_device_plugged(1, true);                // a second one, also ID 1
  const Bytes wire = answers_to(line, sim, test::ping(1));
  EXPECT_GE(wire.size(), 14u);  // something came back...
  dxl::Decoder decoder;
  decoder.feed(wire);
  dxl::Packet p;
  dxl::DecodeResult r;
  while ((r = decoder.next(p)) != dxl::DecodeResult::need_more) {
    EXPECT_NE(r, dxl::DecodeResult::packet) << "a clean packet out of a collision";
  }
  // ...and a broadcast ping gets no clean answer from ID 1 either.
  dxl::Decoder fresh;
  fresh.feed(answers_to(line, sim, test::ping(dxl::kBroadcastId)));
  while ((r = fresh.next(p)) != dxl::DecodeResult::need_more) {
    EXPECT_NE(r, dxl::DecodeResult::packet) << "a clean answer to the broadcast ping";
  }
  // Given an ID of its own (the other unplugged), each answers cleanly again.
  sim.set_device_plugged(1, false);
  EXPECT_EQ(line.transact(test::write(1, xreg::id, {2})).id, 2);
  sim.set_device_plugged(1, true);
  line.send(test::ping(dxl::kBroadcastId));
  const auto both = line.read_status(2);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].id, 1);
  EXPECT_EQ(both[1].id, 2);
}

TEST(ServoLine, FeetechServosHearTheirBaudAndCollide) {
  BusConfig config;
  config.name = "arm";
  config.protocol = "feetech_sts";
  for (int id : {2, 3}) {
    ActuatorBinding b;
    b.joint = "j" + std::to_string(id);
    b.device_id = id;
    config.actuators.push_back(b);
  }
  ManualClock clock{0};
  sim::FeetechSimBus sim(config, ft::Series::sts, clock, ServoStartup{true, nullptr});
  sim.start();
  const Bytes ping1 = {0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB};
  test::PtyClient line(sim.endpoint(), 500'000);
  send_unheard(line, sim, ping1);
  EXPECT_TRUE(line.silent(kQuiet));
  line.set_baud(1'000'000);
  line.send(ping1);
  EXPECT_EQ(line.read_raw(6), Bytes({0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC}));
  sim.set_device_plugged(1, true);
  const Bytes wire = answers_to(line, sim, ping1);
  EXPECT_EQ(wire.size(), 7u);  // two 6-byte packets, the second a byte behind
  EXPECT_NE(wire, Bytes({0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC}));
}

}  // namespace
}  // namespace animrt
