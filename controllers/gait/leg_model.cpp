// The balance reflex applied through a figure's legs (see leg_model.hpp).

#include "animrt/controllers/gait/leg_model.hpp"

namespace animrt {

void apply_balance(const BalanceReflex& reflex, LegModel& legs, std::span<double> targets,
                   std::span<double> scratch) {
  for (std::size_t leg = 0; leg < legs.leg_count(); ++leg) {
    if (!legs.on_ground(leg)) continue;
    const double stretch = reflex.stretch(legs.where(leg), true);
    const std::span<const int> joints = legs.joints(leg);
    const std::span<double> down = scratch.first(joints.size());
    const std::span<double> delta = scratch.subspan(joints.size(), joints.size());
    legs.down_per_rad(leg, down);
    if (!leg_stretch_to_joints(stretch, down, delta)) continue;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      targets[static_cast<std::size_t>(joints[i])] += delta[i];
    }
  }
}

}  // namespace animrt
