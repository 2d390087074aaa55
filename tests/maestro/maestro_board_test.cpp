// The simulated Maestro's output against the figures the user's guide gives
// for its speed and acceleration limits, and its error register.

#include "animrt/sim/maestro/maestro_board.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace animrt::sim {
namespace {

constexpr Nanos kMs = 1'000'000;

struct Rig {
  std::vector<MaestroChannelSetup> setup{{0, 500, 2500}, {1, 500, 2500}};
  MaestroBoard board{12, 6, setup, 0};
  std::vector<std::uint8_t> out;

  void send(std::uint8_t command, int channel, int value, Nanos t) {
    maestro::Command c;
    c.command = command;
    c.channel = static_cast<std::uint8_t>(channel);
    c.value = static_cast<std::uint16_t>(value);
    board.handle(c, t, out);
  }
  // Time (ms) until channel 0's output reaches `target`, stepping 10 ms.
  double time_to(std::uint16_t target, Nanos from, std::vector<double>* steps = nullptr) {
    std::uint16_t last = board.position(0);
    for (Nanos t = from; t < from + 60'000 * kMs; t += 10 * kMs) {
      board.advance(t);
      if (steps) steps->push_back(std::abs(board.position(0) - static_cast<double>(last)));
      last = board.position(0);
      if (board.position(0) == target) return static_cast<double>(t - from) / kMs;
    }
    return -1;
  }
};

TEST(MaestroBoard, SpeedLimitAsInTheGuide) {
  // Speed 140 (3.5 us/ms): 1000 us -> 1350 us takes 100 ms.
  Rig r;
  r.send(maestro::cmd::set_speed, 0, 140, 0);
  r.send(maestro::cmd::set_target, 0, 4000, 0);  // off -> first target: at once
  EXPECT_EQ(r.board.position(0), 4000);
  r.send(maestro::cmd::set_target, 0, 5400, 0);
  r.board.advance(50 * kMs);
  EXPECT_EQ(r.board.position(0), 4700);
  EXPECT_DOUBLE_EQ(r.time_to(5400, 50 * kMs) + 50, 100);
}

TEST(MaestroBoard, SlowestSpeedTakesFortySecondsFromOneToTwoMs) {
  Rig r;
  r.send(maestro::cmd::set_target, 0, 4000, 0);
  r.send(maestro::cmd::set_speed, 0, 1, 0);
  r.send(maestro::cmd::set_target, 0, 8000, 0);
  EXPECT_DOUBLE_EQ(r.time_to(8000, 0), 40'000);
}

TEST(MaestroBoard, SlowestAccelerationTakesAboutThreeSecondsAndRampsSmoothly) {
  Rig r;
  r.send(maestro::cmd::set_target, 0, 4000, 0);
  r.send(maestro::cmd::set_acceleration, 0, 1, 0);
  r.send(maestro::cmd::set_target, 0, 8000, 0);
  std::vector<double> steps;
  const double ms = r.time_to(8000, 0, &steps);
  EXPECT_GT(ms, 2500);
  EXPECT_LT(ms, 4000);
  // The step per tick grows and shrinks by about 1/8 quarter-us per tick.
  for (std::size_t k = 1; k < steps.size(); ++k) {
    EXPECT_LE(std::abs(steps[k] - steps[k - 1]), 1.0 + 1e-9) << "tick " << k;
  }
}

TEST(MaestroBoard, NoLimitsMeansTheOutputJumpsAndTargetsAreClamped) {
  Rig r;
  r.send(maestro::cmd::set_target, 1, 6000, 0);
  EXPECT_EQ(r.board.position(1), 6000);
  r.send(maestro::cmd::set_target, 1, 12000, 0);  // 3000 us > max 2500 us
  EXPECT_EQ(r.board.position(1), 10000);
  r.send(maestro::cmd::set_target, 1, 0, 0);
  EXPECT_EQ(r.board.position(1), 0);  // off
}

TEST(MaestroBoard, BadCommandsSetTheProtocolBitAndSendServosHome) {
  Rig r;
  r.send(maestro::cmd::set_target, 0, 6000, 0);
  r.send(maestro::cmd::set_target, 9, 6000, 0);  // a 6-channel board has no channel 9
  EXPECT_EQ(r.board.errors(), maestro::error_bit::serial_protocol);
  EXPECT_EQ(r.board.position(0), 0);  // home = off
  r.send(maestro::cmd::get_errors, 0, 0, 0);
  ASSERT_EQ(r.out.size(), 2u);
  EXPECT_EQ(maestro::decode_answer(r.out.data()), maestro::error_bit::serial_protocol);
  EXPECT_EQ(r.board.errors(), 0);  // Get Errors clears
}

TEST(MaestroBoard, SerialTimeoutSendsServosHomeWhenTheHostGoesSilent) {
  Rig r;
  r.board.set_serial_timeout(50 * kMs);
  r.send(maestro::cmd::set_target, 0, 6000, 0);
  r.send(maestro::cmd::set_target, 1, 7000, 40 * kMs);  // the latest command: at 40 ms
  r.board.advance(89 * kMs);
  EXPECT_EQ(r.board.errors(), 0);
  EXPECT_EQ(r.board.position(0), 6000);
  r.board.advance(95 * kMs);
  EXPECT_EQ(r.board.errors(), maestro::error_bit::serial_timeout);
  EXPECT_EQ(r.board.position(0), 0);  // home = off: the servo goes limp
  EXPECT_EQ(r.board.position(1), 0);
  r.send(maestro::cmd::get_errors, 0, 0, 100 * kMs);
  ASSERT_EQ(r.out.size(), 2u);
  EXPECT_EQ(maestro::decode_answer(r.out.data()), maestro::error_bit::serial_timeout);
  // Fed by that Get Errors: a target now holds until 50 ms of silence again.
  r.send(maestro::cmd::set_target, 0, 6400, 120 * kMs);
  r.board.advance(169 * kMs);
  EXPECT_EQ(r.board.position(0), 6400);
  EXPECT_EQ(r.board.errors(), 0);
  r.board.advance(171 * kMs);
  EXPECT_EQ(r.board.position(0), 0);
}

TEST(MaestroBoard, NoSerialTimeoutByDefault) {
  Rig r;
  r.send(maestro::cmd::set_target, 0, 6000, 0);
  r.board.advance(60'000 * kMs);
  EXPECT_EQ(r.board.errors(), 0);
  EXPECT_EQ(r.board.position(0), 6000);
}

}  // namespace
}  // namespace animrt::sim
