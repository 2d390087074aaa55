// An SDO answer later than the bus timeout, on a line that is no lockstep
// bus (a real CAN interface with a busy host): the retry takes the first
// try's answer, and the retry's own answer, still on its way, is not taken
// for the answer to the drive's next SDO, which names another object.

#include <gtest/gtest.h>

#include <chrono>
#include <deque>
#include <memory>
#include <string>
#include <thread>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"

namespace animrt::cia402_late_sdo_test {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::uint8_t kNode = 32;

// A drive's SDO server on a scripted line: every upload is answered with
// the value `value_of` gives (the device type says CiA 402), every download
// acknowledged; the answers to the first `late_answers` requests leave
// `late` after their request, the others at once.
class ScriptedDrive final : public CanFrameTransport {
 public:
  int late_answers = 0;
  std::chrono::microseconds late{0};

  const std::string& interface() const override { return name_; }
  void set_filters(std::span<const can_filter>) override {}
  bool send(const can_frame& f) override {
    if (f.can_id != canopen::kRsdoBase + kNode) return true;  // NMT, SYNC: no answer
    const canopen::Sdo s = canopen::parse_sdo(f);
    can_frame a{};
    if (s.kind == canopen::SdoKind::upload_request) {
      const std::uint32_t value = s.index == cia402::obj::device_type ? 0x00020192u : 0u;
      a = canopen::sdo_upload_response(kNode, s.index, s.subindex, value, 4);
    } else {
      a = canopen::sdo_download_response(kNode, s.index, s.subindex);
    }
    auto at = Clock::now();
    if (late_answers > 0) {
      --late_answers;
      at += late;
    }
    queue_.push_back({at, a});
    return true;
  }
  bool receive(can_frame& frame, std::chrono::microseconds timeout) override {
    const auto until = Clock::now() + timeout;
    if (queue_.empty() || queue_.front().at > until) {
      std::this_thread::sleep_until(until);
      return false;
    }
    std::this_thread::sleep_until(queue_.front().at);
    frame = queue_.front().frame;
    queue_.pop_front();
    return true;
  }
  const CanErrorCounters& errors() const override { return errors_; }
  bool bus_off() const override { return false; }
  Nanos now() const override {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
        .count();
  }

 private:
  struct Timed {
    Clock::time_point at;
    can_frame frame;
  };
  std::deque<Timed> queue_;
  std::string name_ = "scripted";
  CanErrorCounters errors_;
};

TEST(Cia402LateSdo, ARetriedSdosLaterAnswerIsNotTakenForTheNextSdo) {
  BusConfig config;
  config.name = "hip";
  config.protocol = "cia402";
  config.port = "scripted";
  config.timeout_s = 0.03;
  config.options = Cia402BusOptions{};
  ActuatorBinding b;
  b.joint = "hip";
  b.joint_index = 0;
  b.device_id = kNode;
  b.ticks_per_rad = 65536 / 6.283185307179586;
  b.zero_ticks = 0;
  config.actuators.push_back(b);
  auto owned = std::make_unique<ScriptedDrive>();
  ScriptedDrive& drive = *owned;
  // The upload of 0x1000 (device type) and its retry are answered 1.5
  // timeouts late: the first answer comes during the retry, the second
  // while the host waits for its next SDO's (the heartbeat time, 0x1017).
  drive.late_answers = 2;
  drive.late = std::chrono::microseconds(45'000);
  Cia402Bus bus(config, std::move(owned));
  EXPECT_NO_THROW(bus.configure());
  EXPECT_GE(bus.devices()[0].protocol_errors, 1u);  // the late answer, counted
}

}  // namespace
}  // namespace animrt::cia402_late_sdo_test
