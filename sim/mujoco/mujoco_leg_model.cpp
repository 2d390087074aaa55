// The balance reflex's legs over an MJCF model (see mujoco_leg_model.hpp).

#include "animrt/sim/mujoco/mujoco_leg_model.hpp"

#include <algorithm>

namespace animrt::sim {

MujocoLegModel::MujocoLegModel(const MujocoModel& mm, const mjData* d)
    : mm_(&mm), physics_(d), d_(d) {
  const mjModel* m = mm.model.get();
  std::vector<int> actuator_of_joint(static_cast<std::size_t>(m->njnt), -1);
  for (int j = 0; j < m->njnt; ++j) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    if (name) actuator_of_joint[static_cast<std::size_t>(j)] = mm.actuator_of(name);
  }
  find_legs(actuator_of_joint);
}

MujocoLegModel::MujocoLegModel(const std::string& model_path,
                               const std::vector<std::string>& joint_names, const Location& where)
    : owned_(std::make_shared<const MujocoModel>(load_mujoco_model(model_path))),
      mm_(owned_.get()) {
  const mjModel* m = mm_->model.get();
  own_data_ = make_mujoco_data(*mm_);
  d_ = own_data_.get();
  std::vector<int> robot_joint_of(static_cast<std::size_t>(m->njnt), -1);
  for (std::size_t i = 0; i < joint_names.size(); ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, joint_names[i].c_str());
    const bool hinge = j >= 0 && m->jnt_type[j] == mjJNT_HINGE;
    qpos_.push_back(hinge ? m->jnt_qposadr[j] : -1);
    if (hinge) robot_joint_of[static_cast<std::size_t>(j)] = static_cast<int>(i);
  }
  const int root = m->body_jntadr[mm_->torso_body];
  if (root >= 0 && m->jnt_type[root] == mjJNT_FREE) root_qpos_ = m->jnt_qposadr[root];
  mj_kinematics(m, own_data_.get());
  find_legs(robot_joint_of);
  if (legs_.empty()) {
    throw InputError(where, "model",
                     model_path +
                         ": no foot hangs from a joint of the robot (the balance reflex "
                         "stretches legs through their joints, matched by name)");
  }
}

// Each foot geom's leg: the joints between it and the trunk the player drives,
// and which end and side of the trunk it is on, as the model stands now.
void MujocoLegModel::find_legs(const std::vector<int>& index_of_joint) {
  const mjModel* m = mm_->model.get();
  const mjData* d = d_;
  const double* r = d->xmat + 9 * mm_->torso_body;  // row-major: world = r * body
  const double* c = d->xpos + 3 * mm_->torso_body;
  for (int g : mm_->foot_geoms) {
    Leg leg;
    leg.geom = g;
    const double w[3] = {d->geom_xpos[3 * g] - c[0], d->geom_xpos[3 * g + 1] - c[1],
                         d->geom_xpos[3 * g + 2] - c[2]};
    leg.where.front = (r[0] * w[0] + r[3] * w[1] + r[6] * w[2]) > 0 ? 1.0 : -1.0;
    leg.where.left = (r[1] * w[0] + r[4] * w[1] + r[7] * w[2]) > 0 ? 1.0 : -1.0;
    leg.sole = m->geom_type[g] == mjGEOM_BOX ? m->geom_size[3 * g + 2] : m->geom_size[3 * g];
    for (int b = m->geom_bodyid[g]; b > 0 && b != mm_->torso_body; b = m->body_parentid[b]) {
      for (int j = m->body_jntadr[b]; j >= 0 && j < m->body_jntadr[b] + m->body_jntnum[b]; ++j) {
        const int index = index_of_joint[static_cast<std::size_t>(j)];
        if (index < 0) continue;
        leg.joints.push_back(index);
        leg.dofs.push_back(m->jnt_dofadr[j]);
      }
    }
    if (!leg.joints.empty()) legs_.push_back(std::move(leg));
  }
  jacp_.assign(3 * static_cast<std::size_t>(m->nv), 0.0);
}

std::size_t MujocoLegModel::max_leg_joints() const {
  std::size_t most = 0;
  for (const Leg& leg : legs_) most = std::max(most, leg.joints.size());
  return most;
}

void MujocoLegModel::pose(std::span<const double> positions, const std::array<double, 4>& trunk) {
  if (physics_) {
    physics_contacts();
    return;
  }
  const mjModel* m = mm_->model.get();
  mjData* d = own_data_.get();
  for (std::size_t i = 0; i < qpos_.size() && i < positions.size(); ++i) {
    if (qpos_[i] >= 0) d->qpos[qpos_[i]] = positions[i];
  }
  if (root_qpos_ >= 0) std::copy(trunk.begin(), trunk.end(), d->qpos + root_qpos_ + 3);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  kinematic_contacts();
}

void MujocoLegModel::physics_contacts() {
  const mjData* d = physics_;
  for (Leg& leg : legs_) {
    leg.on_ground = false;
    for (int c = 0; c < d->ncon && !leg.on_ground; ++c) {
      leg.on_ground = d->contact[c].geom1 == leg.geom || d->contact[c].geom2 == leg.geom;
    }
  }
}

void MujocoLegModel::kinematic_contacts() {
  const mjData* d = d_;
  double lowest = 1e9;
  for (const Leg& leg : legs_) lowest = std::min(lowest, d->geom_xpos[3 * leg.geom + 2] - leg.sole);
  const double band = kGroundBandFraction * mm_->hip_height_m;
  for (Leg& leg : legs_) leg.on_ground = d->geom_xpos[3 * leg.geom + 2] - leg.sole <= lowest + band;
}

void MujocoLegModel::down_per_rad(std::size_t index, std::span<double> out) {
  const Leg& leg = legs_[index];
  const mjModel* m = mm_->model.get();
  const int nv = m->nv;
  const mjData* d = d_;
  const double* r = d->xmat + 9 * mm_->torso_body;
  mj_jac(m, d, jacp_.data(), nullptr, d->geom_xpos + 3 * leg.geom, m->geom_bodyid[leg.geom]);
  for (std::size_t i = 0; i < leg.dofs.size(); ++i) {
    const int dof = leg.dofs[i];
    out[i] = -(r[2] * jacp_[dof] + r[5] * jacp_[nv + dof] + r[8] * jacp_[2 * nv + dof]);
  }
}

}  // namespace animrt::sim
