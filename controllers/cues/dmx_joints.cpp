#include "animrt/controllers/cues/dmx_joints.hpp"

#include <algorithm>

namespace animrt {
namespace {

// Zero first and second derivatives at both ends: easing adds no step.
double dmx_smoothstep(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * s * (s * (6.0 * s - 15.0) + 10.0);
}

}  // namespace

DmxJointInputs::DmxJointInputs(std::vector<DmxJoint> joints)
    : joints_(std::move(joints)),
      levels_(std::make_unique<std::atomic<std::uint32_t>[]>(joints_.size())) {}

void DmxJointInputs::frame(std::span<const std::uint8_t> data) {
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const DmxJoint& j = joints_[i];
    const auto last = static_cast<std::size_t>(std::max(j.coarse, j.fine));
    if (last > data.size()) continue;
    const std::uint32_t coarse = data[static_cast<std::size_t>(j.coarse - 1)];
    const std::uint32_t level = j.fine > 0
                                    ? (coarse << 8) | data[static_cast<std::size_t>(j.fine - 1)]
                                    : (coarse << 8) | coarse;  // 255 is full, as 65535 is
    levels_[i].store(level, std::memory_order_relaxed);
  }
  frames_.fetch_add(1, std::memory_order_release);
}

double DmxJointInputs::target(std::size_t i) const {
  const DmxJoint& j = joints_[i];
  const double level = levels_[i].load(std::memory_order_relaxed) / 65535.0;
  return j.min + level * (j.max - j.min);
}

DmxJointSource::DmxJointSource(std::unique_ptr<MotionSource> cues, const DmxJointInputs& inputs,
                               std::vector<JointSpec> joints, double hold_s)
    : cues_(std::move(cues)),
      inputs_(inputs),
      joints_(std::move(joints)),
      hold_s_(hold_s),
      cue_driven_(joints_.size(), false),
      held_(inputs.joints().size(), 0.0) {
  std::vector<bool> driven(joints_.size(), false);
  for (int j : cues_->driven_joints()) {
    cue_driven_[static_cast<std::size_t>(j)] = true;
    driven[static_cast<std::size_t>(j)] = true;
  }
  for (const DmxJoint& d : inputs_.joints()) driven[static_cast<std::size_t>(d.joint)] = true;
  for (std::size_t j = 0; j < driven.size(); ++j) {
    if (driven[j]) driven_.push_back(static_cast<int>(j));
  }
}

void DmxJointSource::sample(double t, std::span<double> targets) const {
  cues_->sample(t, targets);
  const double dt = std::max(0.0, t - last_t_);
  last_t_ = t;
  const std::uint64_t frames = inputs_.frames();
  if (frames != seen_frames_) {
    seen_frames_ = frames;
    last_frame_t_ = t;
    live_ = true;
    for (std::size_t i = 0; i < held_.size(); ++i) held_[i] = inputs_.target(i);
  } else if (live_ && t - last_frame_t_ > hold_s_) {
    live_ = false;
    losses_.fetch_add(1, std::memory_order_relaxed);
  }
  phase_ = std::clamp(phase_ + (live_ ? dt : -dt) / kDmxEaseS, 0.0, 1.0);
  const double w = dmx_smoothstep(phase_);
  const std::vector<DmxJoint>& dmx = inputs_.joints();
  for (std::size_t i = 0; i < dmx.size(); ++i) {
    const auto j = static_cast<std::size_t>(dmx[i].joint);
    const double cue = cue_driven_[j] ? targets[j] : joints_[j].home;
    targets[j] = cue + w * (held_[i] - cue);
  }
}

}  // namespace animrt
