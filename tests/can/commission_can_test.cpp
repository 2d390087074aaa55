// scan --can on the in-process virtual bus: a CiA 402 drive (heartbeat and
// SDO server) and a node that only sends heartbeats are found with their
// identity, and the scan sends nothing but SDO uploads (no NMT, no PDO).

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/virtual_can_bus.hpp"
#include "animrt/bridge/commission/can_scan.hpp"

namespace animrt::commission {
namespace {

using namespace std::chrono_literals;

// Node 5 answers SDO uploads of its identity and sends heartbeats; node 6
// sends heartbeats only. Every frame the scanner sends is kept.
class Nodes {
 public:
  explicit Nodes(std::shared_ptr<VirtualCanBus> bus) : can_(bus->attach()) {
    thread_ = std::thread([this] { run(); });
  }
  ~Nodes() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  std::vector<canid_t> heard() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    return heard_;
  }

 private:
  void run() {
    auto next_beat = std::chrono::steady_clock::now();
    while (!stop_) {
      if (std::chrono::steady_clock::now() >= next_beat) {
        for (canid_t node : {5u, 6u}) {
          can_frame beat{};
          beat.can_id = canopen::kHeartbeatBase + node;
          beat.can_dlc = 1;
          beat.data[0] = 0x7F;  // pre-operational
          can_->send(beat);
        }
        next_beat += 20ms;
      }
      can_frame f{};
      if (!can_->receive(f, 2ms)) continue;
      heard_.push_back(f.can_id & CAN_SFF_MASK);
      if ((f.can_id & CAN_SFF_MASK) != canopen::kRsdoBase + 5) continue;
      const canopen::Sdo sdo = canopen::parse_sdo(f);
      if (sdo.kind != canopen::SdoKind::upload_request) continue;
      std::uint32_t value = 0;
      if (sdo.index == 0x1000) value = 0x00020192;  // CiA 402 drive
      if (sdo.index == 0x1018 && sdo.subindex == 1) value = 0x000000AB;
      if (sdo.index == 0x1018 && sdo.subindex == 2) value = 0x00001234;
      if (sdo.index == 0x1018 && sdo.subindex == 3) value = 0x00010002;
      can_->send(canopen::sdo_upload_response(5, sdo.index, sdo.subindex, value, 4));
    }
  }

  std::unique_ptr<CanFrameTransport> can_;
  std::atomic<bool> stop_{false};
  std::vector<canid_t> heard_;
  std::thread thread_;
};

TEST(CommissionCan, FindsNodesByHeartbeatAndIdentityWithoutNmt) {
  auto bus = VirtualCanBus::named("commission_scan");
  Nodes nodes(bus);
  ScanLimits limits;
  // Listening and answer times generous for a node thread that a loaded
  // machine holds off the CPU; ids 4-6 only, so a silent id costs little.
  limits.answer_timeout = 500ms;
  limits.first_id = 4;
  limits.last_id = 6;
  ScanResult result;
  scan_canopen("virtual:commission_scan", 500ms, limits, result);
  const std::vector<canid_t> heard = nodes.heard();

  ASSERT_EQ(result.devices.size(), 2u);
  const FoundDevice& drive = result.devices[0];
  EXPECT_EQ(drive.protocol, "canopen");
  EXPECT_EQ(drive.id, 5);
  EXPECT_EQ(drive.model, "device type 0x00020192, vendor 0x000000AB product 0x00001234");
  EXPECT_EQ(drive.firmware, "0x00010002");
  EXPECT_EQ(drive.note, "heartbeat: pre-operational");
  EXPECT_EQ(result.devices[1].id, 6);
  EXPECT_NE(result.devices[1].note.find("no SDO answer"), std::string::npos);
  // Only SDO requests: nothing that changes a node's state.
  ASSERT_FALSE(heard.empty());
  for (canid_t id : heard) {
    EXPECT_GE(id, canopen::kRsdoBase + 4) << std::hex << id;
    EXPECT_LE(id, canopen::kRsdoBase + 6) << std::hex << id;
  }
}

TEST(CommissionCan, AnInterfaceThatIsNotThereIsOneLine) {
  ScanLimits limits;
  ScanResult result;
  try {
    scan_canopen("nosuchcan9", 10ms, limits, result);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("CAN interface nosuchcan9"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace animrt::commission
