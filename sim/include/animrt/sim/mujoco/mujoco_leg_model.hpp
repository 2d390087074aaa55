#pragma once
// The balance reflex's legs (LegModel, leg_model.hpp) over an MJCF model.
//
// Two kinds. On physics (the fitness walk): the pose is the physics' own,
// contacts are the physics' contacts, and a leg's joints index actuators.
// On the runtime: the figure's model posed by forward kinematics at the
// robot joints' targets with the trunk at the IMU's attitude, a leg's joints
// index robot joints (matched by name), and a foot is on the ground when its
// sole is within kGroundBandFraction of the hip height of the lowest sole:
// the runtime has no foot switches, and the lowest feet are the ones that
// carry the figure.

#include <memory>
#include <string>
#include <vector>

#include "animrt/controllers/gait/leg_model.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::sim {

// A sole this close to the lowest one (fraction of the hip height) is down.
constexpr double kGroundBandFraction = 0.02;

class MujocoLegModel final : public LegModel {
 public:
  // On the physics: `d` is the walk's data, read at each pose().
  MujocoLegModel(const MujocoModel& mm, const mjData* d);
  // On the runtime: the model at `model_path` for the robot's joints. Throws
  // InputError at `where` when the model does not load or no leg's joint is
  // a robot joint.
  MujocoLegModel(const std::string& model_path, const std::vector<std::string>& joint_names,
                 const Location& where);

  std::size_t leg_count() const override { return legs_.size(); }
  BalanceLeg where(std::size_t leg) const override { return legs_[leg].where; }
  std::span<const int> joints(std::size_t leg) const override { return legs_[leg].joints; }
  void pose(std::span<const double> positions, const std::array<double, 4>& trunk) override;
  bool on_ground(std::size_t leg) const override { return legs_[leg].on_ground; }
  void down_per_rad(std::size_t leg, std::span<double> out) override;
  std::size_t max_leg_joints() const override;

 private:
  struct Leg {
    int geom = -1;
    BalanceLeg where;
    std::vector<int> joints;  // actuators (physics) or robot joints (runtime)
    std::vector<int> dofs;    // the model's dof of each
    double sole = 0.0;        // how far the geom's bottom is below its centre
    bool on_ground = false;
  };
  void find_legs(const std::vector<int>& index_of_joint);
  void physics_contacts();
  void kinematic_contacts();

  std::shared_ptr<const MujocoModel> owned_;
  const MujocoModel* mm_;
  const mjData* physics_ = nullptr;  // the walk's data, or null on the runtime
  MujocoData own_data_{nullptr, mj_deleteData};
  const mjData* d_ = nullptr;  // whichever is posed
  std::vector<int> qpos_;      // per robot joint: qpos address, -1 when absent
  int root_qpos_ = -1;         // the trunk's free joint, -1 when fixed
  std::vector<Leg> legs_;
  std::vector<double> jacp_;
};

}  // namespace animrt::sim
