// Two servos answering under each other's ids (a wiring or id mistake): the
// lf_hip and lf_knee answers come back swapped. Each servo follows its own
// commands, so nothing times out; only the following-error watch can tell,
// and it must end the run with a fault instead of walking on.

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace animrt {
namespace {

// Passes every call through and swaps the positions of two devices on read.
class SwappedAnswers final : public ActuatorBus {
 public:
  SwappedAnswers(std::unique_ptr<ActuatorBus> inner, std::size_t a, std::size_t b)
      : inner_(std::move(inner)), a_(a), b_(b) {}
  const BusConfig& config() const override { return inner_->config(); }
  void configure() override { inner_->configure(); }
  void activate() override { inner_->activate(); }
  void arm_device_guard() override { inner_->arm_device_guard(); }
  void deactivate() override { inner_->deactivate(); }
  void read(std::span<double> positions) override {
    inner_->read(positions);
    if (swap) std::swap(positions[a_], positions[b_]);
  }
  void write(std::span<const double> positions) override { inner_->write(positions); }
  std::span<DeviceStatus> devices() override { return inner_->devices(); }
  bool swap = true;

 private:
  std::unique_ptr<ActuatorBus> inner_;
  std::size_t a_, b_;
};

RunSummary run_quadruped(bool swapped) {
  SimulatedBackend simulated;
  FigureOptions lockstep;
  lockstep.lockstep = true;
  lockstep.edit = [](RobotConfig& config) {
    for (auto& bus : config.buses) bus.timeout_s = 0.05;
  };
  lockstep.wrap_bus = [swapped](std::unique_ptr<ActuatorBus> bus, std::size_t) {
    auto answers = std::make_unique<SwappedAnswers>(std::move(bus), 0, 1);
    answers->swap = swapped;
    return std::unique_ptr<ActuatorBus>(std::move(answers));
  };
  Figure figure(load_robot(std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml"),
                simulated, lockstep);
  RunOptions options = figure.run_options();
  options.raise_device_threads = nullptr;
  options.duration_s = 6.0;
  return figure.run(options);
}

TEST(WrongIds, SwappedServosAreAFollowingErrorFault) {
  const RunSummary s = run_quadruped(true);
  EXPECT_EQ(s.end_reason, EndReason::fault) << format_summary(s);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_FALSE(s.faults.empty());
  EXPECT_NE(s.faults[0].find("RMS following error"), std::string::npos) << s.faults[0];
  const bool names_one = s.faults[0].find("(lf_hip)") != std::string::npos ||
                         s.faults[0].find("(lf_knee)") != std::string::npos;
  EXPECT_TRUE(names_one) << s.faults[0];
  EXPECT_LT(s.motion_time_s, 6.0);
}

TEST(WrongIds, TheSameRunWithTheRightIdsWalksToTheEnd) {
  const RunSummary s = run_quadruped(false);
  EXPECT_EQ(s.end_reason, EndReason::duration) << format_summary(s);
  EXPECT_TRUE(s.faults.empty());
}

}  // namespace
}  // namespace animrt
