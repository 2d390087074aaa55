#pragma once
// The evolver's GaitSimulator on MuJoCo: one mjData per simulator over a
// shared read-only model. A walk starts standing in the gait's mean pose
// over a stride (feet on the floor), settles, then plays the gait through
// the position actuators, blended in over the first cycle: warm-up cycles,
// then measured cycles. A gait with `balance:`
// walks with its balance reflex added to the curves (legs on the ground
// stretched against the trunk's roll and pitch; balance_reflex.hpp).
//
// Measures: forward (+x) speed of the torso, stride length from successive
// landings of each foot (first to last, per stride period), duty factor from foot contacts, energy
// as sum |actuator force x velocity| dt per cycle. The walk counts as a fall (and stops) when the
// torso drops below half its standing height, tilts more than 60 degrees, touches the
// floor, or the physics goes unstable (has_fallen).

#include <memory>

#include "animrt/controllers/gait/gait_simulator.hpp"
#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::sim {

class MujocoGaitSimulator final : public evolve::GaitSimulator {
 public:
  explicit MujocoGaitSimulator(std::shared_ptr<const MujocoModel> model);
  const evolve::ModelInfo& info() const override { return info_; }
  evolve::GaitMeasures walk(const GaitFile& gait, const evolve::WalkSettings& settings) override;

 private:
  std::shared_ptr<const MujocoModel> model_;
  MujocoData data_;
  evolve::ModelInfo info_;
};

class MujocoGaitSimulatorFactory final : public evolve::GaitSimulatorFactory {
 public:
  explicit MujocoGaitSimulatorFactory(const std::string& model_path);
  std::unique_ptr<evolve::GaitSimulator> make() const override;
  const MujocoModel& model() const { return *model_; }

 private:
  std::shared_ptr<const MujocoModel> model_;
};

// Places the model standing in `targets` (one angle per actuator, clamped to
// the joint ranges) with its lowest foot just touching the floor, at rest.
void place_standing(const MujocoModel& model, mjData* d, const double* targets);

// Whether the model has fallen: torso below half of `standing_z`, tilted
// more than 60 degrees, a geom of the torso body touching a geom of the
// world body (the floor; not the figure's own limbs), or
// non-finite state.
bool has_fallen(const MujocoModel& model, const mjData* d, double standing_z);

}  // namespace animrt::sim
