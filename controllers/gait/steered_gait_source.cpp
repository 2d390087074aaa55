// Steered playback of a gait (see steered_gait_source.hpp).

#include "animrt/controllers/gait/steered_gait_source.hpp"

#include <algorithm>
#include <cmath>

#include "animrt/controllers/gait/froude.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {
namespace {

constexpr int kMeanSamples = 256;

double smoothstep(double u) { return u * u * (3.0 - 2.0 * u); }

double step_toward(double value, double goal, double max_step) {
  return value + std::clamp(goal - value, -max_step, max_step);
}

}  // namespace

SteeredGaitSource::SteeredGaitSource(const GaitSteering& steering, double native_frequency_hz,
                                     std::vector<Expression> curves, std::vector<Drive> drives)
    : steering_(steering), curves_(std::move(curves)), drives_(std::move(drives)) {
  for (const Drive& d : drives_) driven_.push_back(d.joint);
  for (const Expression& c : curves_) {
    // Summed as fractions: a curve that is finite but huge must not
    // overflow into an infinite mean.
    double mean = 0.0;
    for (int i = 0; i < kMeanSamples; ++i) {
      mean += c.eval(static_cast<double>(i) / kMeanSamples) / kMeanSamples;
    }
    means_.push_back(mean);
  }
  const double h = steering_.hip_height_m;
  const double native_froude = froude_for_stride_frequency(native_frequency_hz, h);
  native_speed_ = froude_velocity(native_froude, h);
  native_length_ = froude_stride_length(native_froude, h);
  min_speed_ = steering_.min_speed_m_s();
  max_speed_ = steering_.max_speed_m_s();
  native_frequency_hz_ = native_frequency_hz;
  blend_time_s_ = 1.0 / frequency_at(min_speed_);
  stand_time_s_ = blend_time_s_;
  target_speed_ = std::clamp(native_speed_, min_speed_, max_speed_);
}

double SteeredGaitSource::frequency_at(double speed) const {
  if (steering_.fixed_cadence) return native_frequency_hz_;
  const double h = steering_.hip_height_m;
  return froude_stride_frequency(speed / std::sqrt(kStandardGravity * h), h);
}

double SteeredGaitSource::length_ratio_at(double speed) const {
  if (steering_.fixed_cadence) return speed / native_speed_;
  const double h = steering_.hip_height_m;
  return froude_stride_length(speed / std::sqrt(kStandardGravity * h), h) / native_length_;
}

void SteeredGaitSource::steer(const MotionCommand& command) {
  const double v = command.speed_m_s;
  target_speed_ = (std::isfinite(v) && v >= min_speed_) ? std::min(v, max_speed_) : 0.0;
  const double w = std::isfinite(command.turn_rad_s) ? command.turn_rad_s : 0.0;
  target_turn_ = std::clamp(w, -steering_.max_turn_rad_s, steering_.max_turn_rad_s);
  // Under the slowest walk a turn is a turn on the spot, where the gait can.
  target_spot_ = target_speed_ == 0.0 && target_turn_ != 0.0 && steering_.turn_on_the_spot;
}

double SteeredGaitSource::wind_down(double t, double granted_s) {
  if (!(granted_s > 0.0)) return 0.0;
  advance(t);
  target_speed_ = 0.0;
  target_turn_ = 0.0;
  target_spot_ = false;
  // The blend falls linearly at 1 / blend_time_s_ (a turn on the spot blends
  // out as fast), faster when the stop grants less time: it stands in time.
  const double left = std::max(blend_, spot_);
  stand_time_s_ = std::min(blend_time_s_, granted_s / std::max(left, 1e-9));
  return left * stand_time_s_;
}

MotionCommand SteeredGaitSource::current() const {
  if (!started_) return {0.0, 0.0};
  return {speed_ * smoothstep(blend_) * (1.0 - smoothstep(spot_)), turn_};
}

void SteeredGaitSource::reset(double t) const {
  const bool walking = target_speed_ > 0.0 || target_spot_;
  started_ = true;
  phase_ = 0.0;
  speed_ = target_speed_ > 0.0 ? target_speed_ : min_speed_;
  turn_ = walking ? target_turn_ : 0.0;
  blend_ = walking ? 1.0 : 0.0;
  spot_ = target_spot_ ? 1.0 : 0.0;
  // As if it had walked at this command since t = 0 (the unsteered gait's
  // phase at a constant speed).
  phase_ = frequency_at(speed_) * blend_ * t;
  last_t_ = t;
}

void SteeredGaitSource::advance(double t) const {
  if (!started_ || t <= 0.0 || t < last_t_) {
    reset(t);
    return;
  }
  const double dt = t - last_t_;
  last_t_ = t;
  const bool walking = target_speed_ > 0.0 || target_spot_;
  speed_ = step_toward(speed_, target_speed_ > 0.0 ? target_speed_ : min_speed_,
                       steering_.max_acceleration_m_s2 * dt);
  blend_ = std::clamp(blend_ + (walking ? dt / blend_time_s_ : -dt / stand_time_s_), 0.0, 1.0);
  // Into and out of the turn on the spot over a stride, as walk and stand.
  spot_ = std::clamp(spot_ + (target_spot_ ? dt / blend_time_s_ : -dt / stand_time_s_), 0.0, 1.0);
  turn_ = step_toward(turn_, walking ? target_turn_ : 0.0,
                      steering_.max_turn_rad_s * dt / stand_time_s_);
  phase_ += frequency_at(speed_) * smoothstep(blend_) * dt;
}

void SteeredGaitSource::sample(double t, std::span<double> targets) const {
  advance(t);
  const double s = smoothstep(blend_);
  const double spot = smoothstep(spot_);
  const double a0 = steering_.swing_offset;
  const double amplitude = s * (a0 + (1.0 - a0) * length_ratio_at(speed_));
  const double half_track = 0.5 * steering_.track_width_m;
  // Positive turn is to the left: the left side is inside.
  double left = amplitude * std::max(0.0, (speed_ - turn_ * half_track) / speed_);
  double right = amplitude * std::max(0.0, (speed_ + turn_ * half_track) / speed_);
  // On the spot each side swings as for walking -+turn x half the spot
  // track (the inner side backward), about the swing that walks nowhere.
  const double spot_half_track =
      0.5 *
      (steering_.spot_track_width_m > 0.0 ? steering_.spot_track_width_m : steering_.track_width_m);
  const double b0 = steering_.spot_swing_offset;
  const double per_speed = (1.0 - a0) * length_ratio_at(min_speed_) / min_speed_;
  left += spot * (s * (b0 - per_speed * turn_ * spot_half_track) - left);
  right += spot * (s * (b0 + per_speed * turn_ * spot_half_track) - right);
  // A yaw angle d turns the walk at about v tan(d) / wheelbase: the same turn
  // rate at a faster walk needs a smaller angle. On the spot the yaw joints
  // rest: steered legs that step in place drift the figure.
  const double yaw =
      steering_.max_turn_rad_s > 0.0
          ? s * (1.0 - spot) * (turn_ / steering_.max_turn_rad_s) * (min_speed_ / speed_)
          : 0.0;
  for (const Drive& d : drives_) {
    if (static_cast<std::size_t>(d.joint) >= targets.size()) continue;
    const auto c = static_cast<std::size_t>(d.curve);
    const double value = curves_[c].eval(phase_ - d.phase);
    double deg = 0.0;
    if (d.side == kYaw) {
      deg = d.gain * yaw * value + d.offset_deg;
    } else {
      double scale = d.lift ? s : amplitude;
      if (!d.lift && d.side == kLeft) scale = left;
      if (!d.lift && d.side == kRight) scale = right;
      deg = d.gain * (means_[c] + scale * (value - means_[c])) + d.offset_deg;
    }
    targets[static_cast<std::size_t>(d.joint)] = deg_to_rad(deg);
  }
}

}  // namespace animrt
