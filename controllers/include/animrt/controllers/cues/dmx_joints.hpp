#pragma once
// A lighting desk puppeteers joints: a DMX channel (8-bit, or a coarse and a
// fine channel for 16 bits) maps linearly onto a range of a joint. Frames
// arrive on a receiver's thread (Art-Net, sACN) into a lock-free mailbox;
// the cycle reads the newest levels. The joints' targets then pass the
// safety filter as every target does, so a fader slammed across moves the
// joint at its velocity and acceleration limits, never in a jump.
//
// On signal loss a joint does what a lighting fixture does: it holds the
// last value, for `hold_s` after the last frame; then it eases back to what
// the cues play (its home pose where no cue drives it). When frames come
// again it eases over to them.

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {

struct DmxJoint {
  int joint = 0;                // robot joint index
  int coarse = 1;               // channel 1-512
  int fine = 0;                 // channel 1-512 of the low byte, 0: 8-bit
  double min = 0.0, max = 0.0;  // the joint's target at level 0 and at full (rad, or m)
};

// How long the ease from held DMX values to the cues (and back) takes.
inline constexpr double kDmxEaseS = 1.0;

class DmxJointInputs {
 public:
  explicit DmxJointInputs(std::vector<DmxJoint> joints);

  // A receiver's thread: a frame's channels (channel 1 is data[0]). A frame
  // too short to hold a joint's channels leaves that joint as it was.
  void frame(std::span<const std::uint8_t> data);

  // Any thread.
  const std::vector<DmxJoint>& joints() const { return joints_; }
  std::uint64_t frames() const { return frames_.load(std::memory_order_acquire); }
  // Joint i's target (rad, or m) from the newest level.
  double target(std::size_t i) const;

 private:
  std::vector<DmxJoint> joints_;
  std::unique_ptr<std::atomic<std::uint32_t>[]> levels_;  // 0-65535
  std::atomic<std::uint64_t> frames_{0};
};

// The cues' motion with the DMX joints on top.
class DmxJointSource final : public MotionSource {
 public:
  DmxJointSource(std::unique_ptr<MotionSource> cues, const DmxJointInputs& inputs,
                 std::vector<JointSpec> joints, double hold_s);

  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override;
  void steer(const MotionCommand& command) override { cues_->steer(command); }
  void sense(const Sensors& sensors) override { cues_->sense(sensors); }
  // The DMX joints follow their channels while the cues wind down.
  double wind_down(double t, double granted_s) override { return cues_->wind_down(t, granted_s); }
  void control(const ShowCommand& command, double t) override { cues_->control(command, t); }
  ShowPosition show_position(double t) const override { return cues_->show_position(t); }
  void start(const MotionClock& clock) override { cues_->start(clock); }
  void stop() override { cues_->stop(); }

  // Any thread: how often the stream was lost (held, then eased back).
  std::uint64_t losses() const { return losses_.load(std::memory_order_relaxed); }

 private:
  std::unique_ptr<MotionSource> cues_;
  const DmxJointInputs& inputs_;
  std::vector<JointSpec> joints_;
  double hold_s_;
  std::vector<int> driven_;
  std::vector<bool> cue_driven_;
  mutable std::atomic<std::uint64_t> losses_{0};
  // The cycle's alone.
  mutable std::uint64_t seen_frames_ = 0;
  mutable double last_frame_t_ = 0.0;
  mutable double last_t_ = 0.0;
  mutable bool live_ = false;
  mutable double phase_ = 0.0;  // 0: the cues, 1: the DMX values; eased between
  mutable std::vector<double> held_;
};

}  // namespace animrt
