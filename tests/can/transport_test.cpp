// The in-process virtual CAN bus (delivery, filters, overflow, error frames,
// bus-off) and SocketCAN's plain error where the kernel has no CAN.

#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <chrono>
#include <string>

#include "animrt/bridge/can/socketcan.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

using std::chrono::microseconds;

can_frame frame(canid_t id, std::uint8_t len, std::uint8_t first = 0) {
  can_frame f{};
  f.can_id = id;
  f.len = len;
  f.data[0] = first;
  return f;
}

TEST(VirtualCan, DeliversToOthersNotToTheSender) {
  auto bus = std::make_shared<VirtualCanBus>("t1");
  auto a = bus->attach();
  auto b = bus->attach();
  auto c = bus->attach();
  ASSERT_TRUE(a->send(frame(0x123, 2, 7)));
  can_frame got;
  EXPECT_FALSE(a->receive(got, microseconds(0)));
  ASSERT_TRUE(b->receive(got, microseconds(0)));
  EXPECT_EQ(got.can_id, 0x123u);
  EXPECT_EQ(got.data[0], 7);
  ASSERT_TRUE(c->receive(got, microseconds(1000)));
  EXPECT_FALSE(c->receive(got, microseconds(0)));
  EXPECT_EQ(a->interface(), "virtual:t1");
}

TEST(VirtualCan, FiltersAsSocketCan) {
  auto bus = std::make_shared<VirtualCanBus>("t2");
  auto tx = bus->attach();
  auto rx = bus->attach();
  const can_filter filters[] = {{0x180, 0x780}, {0x701, CAN_SFF_MASK}};
  rx->set_filters(filters);
  tx->send(frame(0x185, 6));
  tx->send(frame(0x205, 6));
  tx->send(frame(0x701, 1));
  tx->send(frame(0x702, 1));
  can_frame got;
  ASSERT_TRUE(rx->receive(got, microseconds(0)));
  EXPECT_EQ(got.can_id, 0x185u);
  ASSERT_TRUE(rx->receive(got, microseconds(0)));
  EXPECT_EQ(got.can_id, 0x701u);
  EXPECT_FALSE(rx->receive(got, microseconds(0)));
}

TEST(VirtualCan, FullQueueCountsAnOverflow) {
  auto bus = std::make_shared<VirtualCanBus>("t3");
  auto tx = bus->attach();
  auto rx = bus->attach();
  for (std::size_t i = 0; i < VirtualCanBus::kQueueFrames + 3; ++i) tx->send(frame(0x10, 1));
  can_frame got;
  std::size_t n = 0;
  while (rx->receive(got, microseconds(0))) ++n;
  EXPECT_EQ(n, VirtualCanBus::kQueueFrames);
  EXPECT_EQ(rx->errors().rx_overflows, 3u);
}

TEST(VirtualCan, ErrorFramesAreCountedNotDelivered) {
  auto bus = std::make_shared<VirtualCanBus>("t4");
  auto tx = bus->attach();
  auto rx = bus->attach();
  can_frame passive{};
  passive.can_id = CAN_ERR_CRTL;
  passive.data[1] = CAN_ERR_CRTL_RX_PASSIVE;
  bus->inject_error(passive);
  can_frame lostarb{};
  lostarb.can_id = CAN_ERR_LOSTARB;
  bus->inject_error(lostarb);
  tx->send(frame(0x55, 1));
  can_frame got;
  ASSERT_TRUE(rx->receive(got, microseconds(0)));
  EXPECT_EQ(got.can_id, 0x55u);
  EXPECT_EQ(rx->errors().error_frames, 2u);
  EXPECT_EQ(rx->errors().error_passive, 1u);
  EXPECT_EQ(rx->errors().arbitration_lost, 1u);
  EXPECT_EQ(describe_errors(rx->errors()), "2 error frames (1 error passive, 1 arbitration lost)");
}

// Error frames as the kernel's CAN drivers send them (linux/can/error.h:
// the class in can_id, controller status in data[1], length CAN_ERR_DLC):
// every class is counted, bus-off and restart are told apart, and the end of
// run report names each count.
TEST(CanErrors, EveryKernelErrorClassIsCounted) {
  auto error = [](canid_t cls, std::uint8_t controller = 0) {
    can_frame f{};
    f.can_id = CAN_ERR_FLAG | cls;
    f.len = CAN_ERR_DLC;
    f.data[1] = controller;
    return f;
  };
  CanErrorCounters c;
  EXPECT_EQ(describe_errors(c), "");
  EXPECT_EQ(count_error_frame(error(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING), c), 0);
  EXPECT_EQ(count_error_frame(error(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE), c), 0);
  EXPECT_EQ(count_error_frame(error(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW), c), 0);
  EXPECT_EQ(count_error_frame(error(CAN_ERR_PROT), c), 0);
  EXPECT_EQ(count_error_frame(error(CAN_ERR_ACK), c), 0);
  EXPECT_EQ(count_error_frame(error(CAN_ERR_LOSTARB), c), 0);
  EXPECT_EQ(count_error_frame(error(CAN_ERR_BUSOFF), c), 1);
  EXPECT_EQ(count_error_frame(error(CAN_ERR_RESTARTED), c), -1);
  EXPECT_EQ(c.error_frames, 8u);
  EXPECT_EQ(c.error_warning, 1u);
  EXPECT_EQ(c.error_passive, 1u);
  EXPECT_EQ(c.rx_overflows, 1u);
  EXPECT_EQ(c.protocol_violations, 1u);
  EXPECT_EQ(c.no_ack, 1u);
  EXPECT_EQ(c.arbitration_lost, 1u);
  EXPECT_EQ(c.bus_off, 1u);
  EXPECT_EQ(c.restarts, 1u);
  // One frame may carry several classes (a bit error that sent the
  // controller to error passive): each is counted, the frame once.
  EXPECT_EQ(count_error_frame(error(CAN_ERR_PROT | CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE), c), 0);
  EXPECT_EQ(c.error_frames, 9u);
  EXPECT_EQ(c.protocol_violations, 2u);
  EXPECT_EQ(c.error_passive, 2u);
  c.tx_dropped = 4;
  EXPECT_EQ(describe_errors(c),
            "9 error frames (1 bus-off, 1 restarted, 2 error passive, 1 error warning, "
            "1 arbitration lost, 2 protocol violation, 1 no ack, 1 receive overflow), "
            "4 frames not sent");
}

TEST(VirtualCan, BusOffStopsTrafficUntilRestart) {
  auto bus = std::make_shared<VirtualCanBus>("t5");
  auto tx = bus->attach();
  auto rx = bus->attach();
  bus->set_bus_off(true);
  EXPECT_FALSE(tx->send(frame(0x1, 1)));
  EXPECT_EQ(tx->errors().tx_dropped, 1u);
  can_frame got;
  EXPECT_FALSE(rx->receive(got, microseconds(0)));
  EXPECT_TRUE(rx->bus_off());
  EXPECT_EQ(rx->errors().bus_off, 1u);
  bus->set_bus_off(false);
  EXPECT_TRUE(tx->send(frame(0x2, 1)));
  ASSERT_TRUE(rx->receive(got, microseconds(0)));
  EXPECT_EQ(got.can_id, 0x2u);
  EXPECT_FALSE(rx->bus_off());
  EXPECT_EQ(rx->errors().restarts, 1u);
}

TEST(VirtualCan, ReportsTheSimulationsClock) {
  auto bus = std::make_shared<VirtualCanBus>("t6");
  auto ep = bus->attach();
  ManualClock clock(12345);
  bus->set_clock(&clock);
  EXPECT_EQ(ep->now(), 12345);
  bus->set_clock(nullptr);
  EXPECT_GT(ep->now(), 12345);
}

TEST(VirtualCan, OpenCanNamesTheSameBus) {
  auto a = open_can("virtual:shared_t7");
  auto b = open_can("virtual:shared_t7");
  a->send(frame(0x42, 0));
  can_frame got;
  EXPECT_TRUE(b->receive(got, microseconds(1000)));
}

// On a kernel without CAN (this CI host) the error says so plainly; with CAN
// (the HIL guest), a missing interface is named.
TEST(SocketCan, PlainErrorWithoutKernelSupportOrInterface) {
  const std::string reason = socketcan_unavailable_reason();
  try {
    open_socketcan("animrtcan9");
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("CAN interface animrtcan9: "), std::string::npos) << what;
    if (!reason.empty()) {
      EXPECT_NE(what.find("this kernel has no CAN support"), std::string::npos) << what;
      EXPECT_NE(what.find("AF_CAN"), std::string::npos) << what;
    } else {
      EXPECT_NE(what.find("no such interface"), std::string::npos) << what;
    }
  }
  EXPECT_THROW(open_socketcan("a_name_far_too_long_for_linux"), DeviceError);
}

}  // namespace
}  // namespace animrt
