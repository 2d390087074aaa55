// A CAN node that floods the interface cannot hold a bus past its timeout:
// both buses stop taking frames a bounded number of frames after the deadline.

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/cia402_bus.hpp"
#include "animrt/bridge/can/mit_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

// Always has one more frame that passes the filters but answers nobody.
class FloodTransport final : public CanFrameTransport {
 public:
  explicit FloodTransport(canid_t id, long& calls) : id_(id), calls_(calls) {}
  const std::string& interface() const override { return name_; }
  void set_filters(std::span<const can_filter>) override {}
  bool send(const can_frame&) override { return true; }
  bool receive(can_frame& frame, std::chrono::microseconds) override {
    // A safety net so that an unbounded loop ends the test instead of hanging it.
    if (++calls_ > kGiveUp) return false;
    frame = can_frame{};
    frame.can_id = id_;
    frame.len = 8;
    frame.data[0] = 0x7E;  // no motor of the bus
    return true;
  }
  const CanErrorCounters& errors() const override { return errors_; }
  bool bus_off() const override { return false; }
  Nanos now() const override { return MonotonicClock().now(); }
  static constexpr long kGiveUp = 5'000'000;

 private:
  std::string name_ = "flood";
  canid_t id_;
  long& calls_;
  CanErrorCounters errors_;
};

BusConfig one_motor(const std::string& protocol) {
  BusConfig config;
  config.name = "legs";
  config.protocol = protocol;
  config.port = "flood";
  config.timeout_s = 0.002;
  ActuatorBinding b;
  b.joint = "knee";
  b.joint_index = 0;
  b.device_id = 1;
  if (protocol == "mit") {
    MitMotorOptions m;
    m.min_motor_rad = -1.0;
    m.max_motor_rad = 1.0;
    b.options = m;
  }
  config.actuators.push_back(b);
  return config;
}

TEST(CanFlood, MitBusGivesUpAfterItsTimeout) {
  long calls = 0;
  MitBus bus(one_motor("mit"), std::make_unique<FloodTransport>(0, calls));
  EXPECT_THROW(bus.configure(), DeviceError);  // nobody answered
  EXPECT_LT(calls, FloodTransport::kGiveUp);
}

TEST(CanFlood, Cia402BusSyncCycleGivesUpAfterItsTimeout) {
  long calls = 0;
  // TPDO 1 of a node not on the bus, over and over.
  Cia402Bus bus(one_motor("cia402"), std::make_unique<FloodTransport>(0x180 + 9, calls));
  std::vector<double> q(1, 0.0);
  bus.read(q);
  EXPECT_LT(calls, FloodTransport::kGiveUp);
}

}  // namespace
}  // namespace animrt
