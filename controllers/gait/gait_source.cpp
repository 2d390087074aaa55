// A gait bound to a robot's joints: the MotionSource the real-time loop samples.

#include "animrt/controllers/gait/gait_source.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/controllers/gait/steered_gait_source.hpp"
#include "animrt/core/error.hpp"

namespace animrt {
namespace {

// Strides a plain gait takes to wind down at a stop.
constexpr double kWindDownStrides = 2.0;
constexpr int kGaitMeanSamples = 256;

// Each curve's mean over one stride, summed as fractions so a finite but
// huge curve does not overflow.
std::vector<double> stride_means(const std::vector<Expression>& curves) {
  std::vector<double> means;
  for (const Expression& c : curves) {
    double mean = 0.0;
    for (int i = 0; i < kGaitMeanSamples; ++i) {
      mean += c.eval(static_cast<double>(i) / kGaitMeanSamples) / kGaitMeanSamples;
    }
    means.push_back(mean);
  }
  return means;
}

class GaitSource final : public MotionSource {
 public:
  // One driven joint, everything resolved to indices and numbers at load.
  struct Drive {
    int joint = 0;
    int curve = 0;
    double phase = 0.0;  // stride cycles
    double gain = 1.0;   // sign * scale
    double offset_deg = 0.0;
  };

  GaitSource(double frequency, std::vector<Expression> curves, std::vector<Drive> drives,
             bool walks)
      : frequency_(frequency),
        curves_(std::move(curves)),
        means_(stride_means(curves_)),
        drives_(std::move(drives)),
        walks_(walks) {
    for (const Drive& d : drives_) driven_.push_back(d.joint);
  }

  std::span<const int> driven_joints() const override { return driven_; }

  void sample(double t, std::span<double> targets) const override {
    const double cycles = frequency_ * stride_time(t);
    const double rest = 1.0 - swing_at(t);  // 0 while walking: the curves exactly
    for (const Drive& d : drives_) {
      if (static_cast<std::size_t>(d.joint) >= targets.size()) continue;
      const auto c = static_cast<std::size_t>(d.curve);
      const double value = curves_[c].eval(cycles - d.phase);
      const double deg = d.gain * (value + rest * (means_[c] - value)) + d.offset_deg;
      targets[static_cast<std::size_t>(d.joint)] = deg_to_rad(deg);
    }
  }

  // The walk winds down over the time of kWindDownStrides strides, or over
  // the time the stop grants when that is shorter: every joint's swing
  // about its stride mean and the cadence ease to nothing together (as a
  // steered gait blends to a stand), so the steps shorten and slow and the
  // body slows with them, and the figure stands when the time is up.
  double wind_down(double t, double granted_s) override {
    if (!walks_ || !(granted_s > 0.0)) return 0.0;
    wind_start_ = t;
    wind_length_ = std::min(kWindDownStrides / frequency_, granted_s);
    return wind_length_;
  }

 private:
  // How far into the wind-down motion time t is, 0 to 1 (0 while walking).
  double wind_at(double t) const {
    if (wind_start_ < 0.0 || t <= wind_start_) return 0.0;
    return std::min(1.0, (t - wind_start_) / wind_length_);
  }
  // The swing's scale: 1 while walking, easing to 0 over the wind-down
  // (smoothstep: no jump in the joints' speed at either end).
  double swing_at(double t) const {
    const double u = wind_at(t);
    return 1.0 - u * u * (3.0 - 2.0 * u);
  }
  // The gait's own time, whose rate is the swing's scale: the integral of
  // 1 - smoothstep over the wind-down (half a wind-down's time at its end).
  double stride_time(double t) const {
    const double u = wind_at(t);
    if (u <= 0.0) return t;
    return wind_start_ + wind_length_ * (u - u * u * u + 0.5 * u * u * u * u);
  }

  double frequency_;
  std::vector<Expression> curves_;
  std::vector<double> means_;  // per curve, over one stride: the pose a wound-down walk stands in
  std::vector<Drive> drives_;
  std::vector<int> driven_;
  bool walks_ = true;         // a sway that carries no weight has nothing to wind down
  double wind_start_ = -1.0;  // motion time the wind-down began (-1: walking)
  double wind_length_ = 1.0;  // its length (s)
};

std::string joint_names(std::span<const JointSpec> joints) {
  std::string out;
  for (const auto& j : joints) out += (out.empty() ? "" : ", ") + j.name;
  return out.empty() ? std::string("none") : out;
}

// `gait` has been validated.
std::unique_ptr<MotionSource> source_for(const GaitFile& gait, std::span<const JointSpec> joints) {
  std::vector<Expression> curves;
  curves.reserve(gait.curves.size());
  for (const auto& c : gait.curves) curves.push_back(Expression::compile(c.expression));

  std::vector<GaitSource::Drive> drives;
  for (const GaitJoint& gj : gait.joints) {
    GaitSource::Drive d;
    d.joint = -1;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      if (joints[i].name == gj.name) d.joint = static_cast<int>(i);
    }
    if (d.joint < 0) {
      throw InputError(gj.where, "joints." + gj.name,
                       "no joint named '" + elide(gj.name) +
                           "' in the robot (its joints: " + joint_names(joints) + ")");
    }
    for (std::size_t i = 0; i < gait.curves.size(); ++i) {
      if (gait.curves[i].name == gj.curve) d.curve = static_cast<int>(i);
    }
    d.phase = gait.find_limb(gj.limb)->phase;
    d.gain = gj.sign * gj.scale;
    d.offset_deg = gj.offset_deg;
    drives.push_back(d);
  }
  if (!gait.steering) {
    return std::make_unique<GaitSource>(gait.stride_frequency(), std::move(curves),
                                        std::move(drives), gait.walks);
  }
  const GaitSteering& steering = *gait.steering;
  std::vector<SteeredGaitSource::Drive> steered;
  for (std::size_t i = 0; i < drives.size(); ++i) {
    const GaitJoint& gj = gait.joints[i];
    SteeredGaitSource::Drive d;
    d.joint = drives[i].joint;
    d.curve = drives[i].curve;
    d.phase = drives[i].phase;
    d.gain = drives[i].gain;
    d.offset_deg = drives[i].offset_deg;
    const auto has = [](const std::vector<std::string>& names, const std::string& n) {
      return std::find(names.begin(), names.end(), n) != names.end();
    };
    if (has(steering.left, gj.limb)) d.side = SteeredGaitSource::kLeft;
    if (has(steering.right, gj.limb)) d.side = SteeredGaitSource::kRight;
    if (has(steering.yaw_joints, gj.name)) d.side = SteeredGaitSource::kYaw;
    d.lift = has(steering.lift_curves, gj.curve);
    steered.push_back(d);
  }
  return std::make_unique<SteeredGaitSource>(steering, gait.stride_frequency(), std::move(curves),
                                             std::move(steered));
}

}  // namespace

std::unique_ptr<MotionSource> load_gait_source(const std::string& gait_path,
                                               std::span<const JointSpec> joints) {
  return source_for(load_gait_file(gait_path), joints);
}

std::unique_ptr<MotionSource> make_gait_source(const GaitFile& gait,
                                               std::span<const JointSpec> joints) {
  validate_gait(gait);
  return source_for(gait, joints);
}

}  // namespace animrt
