// A gait with its balance reflex on the runtime (see balanced_gait_source.hpp).

#include "animrt/controllers/gait/balanced_gait_source.hpp"

#include <algorithm>

#include "animrt/core/imu.hpp"

namespace animrt {

BalancedGaitSource::BalancedGaitSource(std::unique_ptr<MotionSource> gait, const GaitBalance& gains,
                                       std::size_t joint_count)
    : gait_(std::move(gait)),
      gains_(gains),
      reflex_(gains),
      measured_(joint_count, 0.0),
      curves_(joint_count, 0.0) {}

void BalancedGaitSource::attach(std::unique_ptr<LegModel> legs) {
  legs_ = std::move(legs);
  scratch_.assign(2 * (legs_ ? legs_->max_leg_joints() : 0), 0.0);
}

void BalancedGaitSource::sense(const Sensors& sensors) {
  measured_known_ = sensors.positions.size() == measured_.size();
  if (measured_known_)
    std::copy(sensors.positions.begin(), sensors.positions.end(), measured_.begin());
  if (!sensors.imu) {
    if (readings_ > 0) ++held_;
    return;
  }
  const ImuReading& r = *sensors.imu;
  // The cycle hands the newest reading every cycle; the part reports at its
  // own rate, so only a new one moves the reflex.
  if (readings_ > 0 && r.time_s <= last_time_s_) return;
  const TrunkUp up = trunk_up(r.quat);
  const double dt = readings_ > 0 ? r.time_s - last_time_s_ : 1.0;
  reflex_.update(TrunkTilt{up.nose_up, up.left_up}, dt);
  trunk_ = r.quat;
  last_time_s_ = r.time_s;
  ++readings_;
}

void BalancedGaitSource::sample(double t, std::span<double> targets) const {
  gait_->sample(t, targets);
  if (!legs_ || readings_ == 0) return;
  // The legs posed where they were measured (or the curves put them), the
  // trunk where the IMU says.
  if (measured_known_) {
    legs_->pose(measured_, trunk_);
  } else {
    std::copy(targets.begin(), targets.end(), curves_.begin());
    legs_->pose(curves_, trunk_);
  }
  apply_balance(reflex_, *legs_, targets, scratch_);
}

}  // namespace animrt
