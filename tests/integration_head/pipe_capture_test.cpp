// Live sound from a FIFO (capture: pipe:PATH), the stand-in for a capture
// device on a machine without a sound card: what is written moves the jaw
// (the writer is the device's clock), and a head whose pipe never gets a
// writer still stops.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "animrt/controllers/head/audio_input.hpp"
#include "animrt/controllers/head/head_source.hpp"
#include "animrt/core/clock.hpp"

namespace animrt::pipe_capture_test {
namespace {

const std::string kSrc = ANIMRT_SOURCE_DIR;

std::vector<JointSpec> joints() {
  std::vector<JointSpec> out(2);
  out[0].name = "yaw";
  out[1].name = "jaw";
  for (JointSpec& j : out) j.limits = {deg_to_rad(-30), deg_to_rad(30), 1, 1};
  return out;
}

std::unique_ptr<MotionSource> piped_head(const std::string& fifo) {
  head::HeadMotionConfig c;
  c.model = kSrc + "/configs/head/model.txt";
  c.capture = std::string(head::kPipeCapturePrefix) + fifo;
  c.yaw.joint = "yaw";
  c.jaw.joint = "jaw";
  return head::make_head_source(c, joints());
}

std::string make_fifo(const std::string& tag) {
  const std::string path = ::testing::TempDir() + "/" + tag + std::to_string(::getpid());
  ::unlink(path.c_str());
  EXPECT_EQ(::mkfifo(path.c_str(), 0600), 0);
  return path;
}

TEST(PipeCapture, WhatIsWrittenOpensTheJaw) {
  const std::string fifo = make_fifo("jaw_fifo");
  auto head = piped_head(fifo);
  MonotonicClock clock;
  head->start(MotionClock{&clock, clock.now(), false});
  int fd = -1;
  for (int i = 0; i < 5000 && fd < 0; ++i) {  // once the head has opened it
    fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_GE(fd, 0);
  std::vector<double> targets(2, 0.0);
  head->sample(0.0, targets);
  EXPECT_EQ(targets[1], 0.0);                  // silence so far: closed
  std::vector<std::int16_t> sound(24000 / 2);  // 0.5 s of a loud voiced sound
  for (std::size_t i = 0; i < sound.size(); ++i)
    sound[i] = static_cast<std::int16_t>(std::lround(
        9000 * std::sin(2 * std::numbers::pi * 180.0 * static_cast<double>(i) / 24000)));
  ::fcntl(fd, F_SETFL, 0);
  ASSERT_EQ(::write(fd, sound.data(), sound.size() * 2), static_cast<ssize_t>(sound.size() * 2));
  double opened = 0;
  for (int i = 0; i < 5000 && opened < deg_to_rad(10); ++i) {
    head->sample(0.0, targets);
    opened = targets[1];
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_GE(opened, deg_to_rad(10));
  ::close(fd);
  head->stop();
  ::unlink(fifo.c_str());
}

TEST(PipeCapture, AHeadWhosePipeNeverGetsAWriterStops) {
  const std::string fifo = make_fifo("silent_fifo");
  auto head = piped_head(fifo);
  MonotonicClock clock;
  head->start(MotionClock{&clock, clock.now(), false});
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  head->stop();  // returns: the test would hang otherwise
  std::vector<double> targets(2, 0.0);
  head->sample(1.0, targets);
  EXPECT_EQ(targets[1], 0.0);
  ::unlink(fifo.c_str());
}

}  // namespace
}  // namespace animrt::pipe_capture_test
