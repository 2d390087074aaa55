#pragma once
// Loading an MJCF model once, to be shared read-only by many mjData (one per
// thread), and the names the rest of animrt relies on: the trunk body
// "torso", foot geoms whose names end in "foot", position actuators on hinge
// joints, and an optional custom numeric "hip_height".

#include <mujoco/mujoco.h>

#include <memory>
#include <string>
#include <vector>

namespace animrt::sim {

struct MujocoModel {
  std::shared_ptr<const mjModel> model;
  std::string file;
  int torso_body = -1;
  std::vector<int> foot_geoms;
  // One entry per actuator, in actuator order.
  std::vector<std::string> actuated_joints;
  std::vector<int> actuator_qpos;  // qpos address of each actuator's joint
  std::vector<int> actuator_dof;   // dof address of each actuator's joint
  double hip_height_m = 0.0;
  double mass_kg = 0.0;

  int actuator_of(const std::string& joint) const;  // -1 when absent
};

// Throws InputError naming the file (and line, when MuJoCo gives one) for a
// missing or invalid model, or one that breaks the conventions above.
MujocoModel load_mujoco_model(const std::string& path);

// MuJoCo's mj_loadXML of `path`, after refusing (InputError at its line
// and attribute) a number in the file that is not finite, which MuJoCo
// takes with a warning and simulates as NaN. MuJoCo's own warnings go to
// standard error as "warning: PATH: ..." (not to the terminal and a
// MUJOCO_LOG.TXT by themselves). Null with MuJoCo's error in `error`.
mjModel* read_mjcf(const std::string& path, std::string& error);

// Throws InputError at the file's timestep attribute (option.timestep) when
// the loaded model's step is outside 10 us to 0.1 s: MuJoCo accepts
// timestep="0", and a run stepping physics up to a time never got there.
void check_mujoco_timestep(const mjModel& model, const std::string& path);

// A data block for `model`, freed with mj_deleteData.
using MujocoData = std::unique_ptr<mjData, void (*)(mjData*)>;
MujocoData make_mujoco_data(const MujocoModel& model);

}  // namespace animrt::sim
