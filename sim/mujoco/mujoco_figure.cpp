// Forward kinematics of an MJCF figure for the dashboard (see mujoco_figure.hpp).

#include "animrt/sim/mujoco/mujoco_figure.hpp"

#include <algorithm>

#include "animrt/core/input_file.hpp"
#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::sim {
namespace {

const char* geom_type_name(int type) {
  switch (type) {
    case mjGEOM_PLANE:
      return "plane";
    case mjGEOM_SPHERE:
      return "sphere";
    case mjGEOM_CAPSULE:
      return "capsule";
    case mjGEOM_ELLIPSOID:
      return "ellipsoid";
    case mjGEOM_CYLINDER:
      return "cylinder";
    case mjGEOM_BOX:
      return "box";
    case mjGEOM_MESH:
      return "mesh";
    default:
      return "other";
  }
}

std::vector<double> geom_size(int type, const mjtNum* size) {
  switch (type) {
    case mjGEOM_SPHERE:
      return {size[0]};
    case mjGEOM_CAPSULE:
    case mjGEOM_CYLINDER:
      return {size[0], size[1]};
    case mjGEOM_BOX:
    case mjGEOM_ELLIPSOID:
      return {size[0], size[1], size[2]};
    default:
      return {};
  }
}

}  // namespace

MujocoFigure::MujocoFigure(const std::string& model_path,
                           const std::vector<std::string>& joint_names, const Location& where)
    : model_(nullptr, mj_deleteModel), data_(nullptr, mj_deleteData) {
  if (const std::string problem = input_file_problem(model_path, kMaxMediaFileBytes);
      !problem.empty()) {
    throw InputError(where, "model", model_path + " " + problem);
  }
  std::string message;
  model_.reset(read_mjcf(model_path, message));
  if (!model_) {
    std::replace(message.begin(), message.end(), '\n', ' ');
    throw InputError(where, "model", model_path + " is not a valid MJCF model: " + message);
  }
  const mjModel* m = model_.get();
  check_mujoco_timestep(*m, model_path);
  data_ = MujocoData(mj_makeData(m), mj_deleteData);

  for (const std::string& name : joint_names) {
    const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    const bool usable = j >= 0 && (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE);
    qpos_.push_back(usable ? m->jnt_qposadr[j] : -1);
    if (usable) ++matched_;
  }
  if (matched_ == 0) {
    throw InputError(where, "model",
                     model_path + " has none of the robot's joints (joints are matched by name)");
  }

  for (int b = 1; b < m->nbody; ++b) {
    FigureBody body;
    const char* name = mj_id2name(m, mjOBJ_BODY, b);
    body.name = name ? name : "body" + std::to_string(b);
    body.parent = m->body_parentid[b] - 1;  // world (0) becomes -1
    for (int g = m->body_geomadr[b]; g >= 0 && g < m->body_geomadr[b] + m->body_geomnum[b]; ++g) {
      FigureGeom geom;
      geom.type = geom_type_name(m->geom_type[g]);
      geom.size = geom_size(m->geom_type[g], m->geom_size + 3 * g);
      std::copy_n(m->geom_pos + 3 * g, 3, geom.pos.begin());
      std::copy_n(m->geom_quat + 4 * g, 4, geom.quat.begin());
      std::copy_n(m->geom_rgba + 4 * g, 4, geom.rgba.begin());
      body.geoms.push_back(std::move(geom));
    }
    bodies_.push_back(std::move(body));
  }
}

MujocoFigure::~MujocoFigure() = default;

void MujocoFigure::pose(std::span<const double> joint_positions, std::span<BodyPose> out) {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  std::copy_n(m->qpos0, m->nq, d->qpos);
  for (std::size_t j = 0; j < qpos_.size() && j < joint_positions.size(); ++j) {
    if (qpos_[j] >= 0) d->qpos[qpos_[j]] = joint_positions[j];
  }
  mj_kinematics(m, d);
  for (std::size_t i = 0; i < out.size() && i + 1 < static_cast<std::size_t>(m->nbody); ++i) {
    const std::size_t b = i + 1;
    std::copy_n(d->xpos + 3 * b, 3, out[i].pos.begin());
    std::copy_n(d->xquat + 4 * b, 4, out[i].quat.begin());
  }
}

}  // namespace animrt::sim
