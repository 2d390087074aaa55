#pragma once
// A gait with `balance:` as it plays on the runtime: the gait's own source
// (plain or steered) with the balance reflex added to its targets, exactly
// as the fitness walk adds it (apply_balance, leg_model.hpp). The trunk's
// attitude comes from the cycle's IMU through sense(); the tilt's rate is
// the difference between successive readings over the time between them.
// The legs are posed at the joints' measured positions when the cycle gives
// them (as the fitness walk reads its physics), else at the curves' targets.
// While the IMU is silent the reflex holds its last tilt and rate, so the
// stretch does not jump (the cycle counts the late readings, and faults a
// stale IMU as it does a silent servo). The legs come from the
// figure's model (attach()); without them the gait plays as its curves.

#include <memory>
#include <vector>

#include "animrt/controllers/gait/balance_reflex.hpp"
#include "animrt/controllers/gait/leg_model.hpp"
#include "animrt/controllers/motion_source.hpp"

namespace animrt {

class BalancedGaitSource final : public MotionSource {
 public:
  BalancedGaitSource(std::unique_ptr<MotionSource> gait, const GaitBalance& gains,
                     std::size_t joint_count);

  // The figure's legs, indexed by robot joint. Before the run, not in it.
  void attach(std::unique_ptr<LegModel> legs);
  bool has_legs() const { return legs_ != nullptr; }
  const GaitBalance& gains() const { return gains_; }

  std::span<const int> driven_joints() const override { return gait_->driven_joints(); }
  void sample(double t, std::span<double> targets) const override;
  void steer(const MotionCommand& command) override { gait_->steer(command); }
  double wind_down(double t, double granted_s) override { return gait_->wind_down(t, granted_s); }
  void sense(const Sensors& sensors) override;
  void start(const MotionClock& clock) override { gait_->start(clock); }
  void stop() override { gait_->stop(); }

  // Cycles sensed with no IMU reading at all after the first one (held).
  std::uint64_t held_cycles() const { return held_; }
  // IMU readings the reflex took.
  std::uint64_t readings() const { return readings_; }

 private:
  std::unique_ptr<MotionSource> gait_;
  GaitBalance gains_;
  BalanceReflex reflex_;
  std::unique_ptr<LegModel> legs_;
  std::array<double, 4> trunk_{1.0, 0.0, 0.0, 0.0};
  double last_time_s_ = 0.0;
  std::uint64_t readings_ = 0;
  std::uint64_t held_ = 0;
  std::vector<double> measured_;  // the joints' last measured positions
  bool measured_known_ = false;
  // Scratch for sample(), which is const: the curves' targets before the reflex.
  mutable std::vector<double> curves_;
  mutable std::vector<double> scratch_;
};

}  // namespace animrt
