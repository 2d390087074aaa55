#pragma once
// What the balance reflex needs of a figure's legs besides the trunk's tilt:
// where each foot sits on the trunk, which joints move it, whether it is on
// the ground, and how far each of those joints moves it down the trunk's
// vertical. Whoever plays a balanced gait supplies it: the fitness walk from
// its physics (true contacts, the physics' Jacobian), the runtime from the
// figure's model posed at the joints' targets and the IMU's attitude (a foot
// is on the ground when it is among the lowest). Implementations live where
// the model does (sim/mujoco); the gait knows only this interface.

#include <array>
#include <cstddef>
#include <span>

#include "animrt/controllers/gait/balance_reflex.hpp"

namespace animrt {

class LegModel {
 public:
  virtual ~LegModel() = default;

  virtual std::size_t leg_count() const = 0;
  virtual BalanceLeg where(std::size_t leg) const = 0;
  // The joints between the trunk and the leg's foot, as indices into the
  // targets the player hands to apply_balance().
  virtual std::span<const int> joints(std::size_t leg) const = 0;

  // The figure with its joints at `positions` (indexed like the targets) and
  // its trunk at attitude `trunk` (w, x, y, z). A model that measures its
  // pose itself (physics) ignores both. Allocation-free.
  virtual void pose(std::span<const double> positions, const std::array<double, 4>& trunk) = 0;

  // At the last pose: whether the leg's foot is on the ground, and how far
  // (m) it moves down the trunk's vertical per radian of each of its joints
  // (`out` sized like joints(leg)).
  virtual bool on_ground(std::size_t leg) const = 0;
  virtual void down_per_rad(std::size_t leg, std::span<double> out) = 0;

  // The most joints any leg has (scratch size for apply_balance).
  virtual std::size_t max_leg_joints() const = 0;
};

// Adds the reflex's stretch of every leg on the ground to `targets` through
// its Jacobian (leg_stretch_to_joints). `scratch` holds at least
// 2 * legs.max_leg_joints() values. Allocation-free.
void apply_balance(const BalanceReflex& reflex, LegModel& legs, std::span<double> targets,
                   std::span<double> scratch);

}  // namespace animrt
