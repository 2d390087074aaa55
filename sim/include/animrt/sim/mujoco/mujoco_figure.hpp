#pragma once
// The runtime's FigureKinematics over an MJCF model: the model's bodies and
// geoms, and body poses from robot joint positions by forward kinematics
// (mj_kinematics). Robot joints are matched to the model's joints by name;
// model joints no robot joint drives stay at their reference position.

#include <memory>
#include <string>
#include <vector>

#include "animrt/core/error.hpp"
#include "animrt/runtime/figure_kinematics.hpp"
#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::sim {

class MujocoFigure final : public FigureKinematics {
 public:
  // Loads `model_path` for the robot joints `joint_names`. Throws InputError
  // at `where` (the robot file's `model` key) when the file does not load or
  // none of the robot's joints is a joint of the model.
  MujocoFigure(const std::string& model_path, const std::vector<std::string>& joint_names,
               const Location& where);
  ~MujocoFigure() override;

  const std::vector<FigureBody>& bodies() const override { return bodies_; }
  void pose(std::span<const double> joint_positions, std::span<BodyPose> out) override;
  // Robot joints the model has (the others are ignored).
  std::size_t matched_joints() const { return matched_; }

 private:
  std::unique_ptr<mjModel, void (*)(mjModel*)> model_;
  MujocoData data_;
  std::vector<FigureBody> bodies_;  // model bodies 1..nbody-1
  std::vector<int> qpos_;           // per robot joint: qpos address, -1 when absent
  std::size_t matched_ = 0;
};

}  // namespace animrt::sim
