// MuJoCo physics behind the simulated servos (see mujoco_physics.hpp).

#include "animrt/sim/mujoco/mujoco_physics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "animrt/core/error.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"

namespace animrt::sim {
namespace {

std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

MujocoJointPhysics::MujocoJointPhysics(const std::string& model_path,
                                       const std::vector<JointSpec>& joints,
                                       const std::string& robot_file, Nanos start)
    : meta_(load_mujoco_model(model_path)),
      model_(mj_copyModel(nullptr, meta_.model.get()), mj_deleteModel),
      data_(make_mujoco_data(meta_)),
      start_(start) {
  if (!model_) throw std::runtime_error("mj_copyModel failed for " + model_path);
  const mjModel* m = model_.get();
  for (const JointSpec& joint : joints) {
    const int a = meta_.actuator_of(joint.name);
    if (a < 0) {
      throw InputError({model_path, 0, 0}, "actuator",
                       "joint '" + elide(joint.name) + "' of " + robot_file +
                           " has no position actuator on a hinge joint of that name in this "
                           "model (it has: " +
                           listed(meta_.actuated_joints) + ")");
    }
    names_.push_back(joint.name);
    actuator_.push_back(a);
  }
  step_ns_ = std::max<Nanos>(1, std::llround(m->opt.timestep * 1e9));
  for (int a = 0; a < m->nu; ++a) {
    gain_.push_back(m->actuator_gainprm[a * mjNGAIN]);
    bias1_.push_back(m->actuator_biasprm[a * mjNBIAS + 1]);
    bias2_.push_back(m->actuator_biasprm[a * mjNBIAS + 2]);
  }
  std::vector<double> pose(static_cast<std::size_t>(m->nu), 0.0);
  for (std::size_t j = 0; j < joints.size(); ++j) pose[actuator_[j]] = joints[j].home;
  place_standing(meta_, data_.get(), pose.data());
  const int torso = meta_.torso_body;
  standing_z_ = data_->xpos[3 * torso + 2];
  x0_ = data_->xpos[3 * torso];
  y0_ = data_->xpos[3 * torso + 1];
  yaw0_ = std::atan2(data_->xmat[9 * torso + 3], data_->xmat[9 * torso]);
}

MujocoJointPhysics::~MujocoJointPhysics() = default;

int MujocoJointPhysics::joint_index(const std::string& joint) const {
  const auto it = std::find(names_.begin(), names_.end(), joint);
  return it == names_.end() ? -1 : static_cast<int>(it - names_.begin());
}

void MujocoJointPhysics::advance(Nanos now) {
  {
    std::lock_guard lock(mutex_);
    step_towards(now);
  }
  party_moved_.notify_all();
}

void MujocoJointPhysics::step_towards(Nanos now) {
  now = std::min(now, slowest_party());
  if (now <= start_) return;
  const auto due = static_cast<std::uint64_t>((now - start_) / step_ns_);
  while (steps_ < due) step();
}

Nanos MujocoJointPhysics::slowest_party() const {
  Nanos slowest = std::numeric_limits<Nanos>::max();
  for (const Party& p : parties_) {
    if (p.waited_for) slowest = std::min(slowest, p.time);
  }
  return slowest;
}

int MujocoJointPhysics::join_lockstep() {
  std::lock_guard lock(mutex_);
  parties_.push_back({start_, true});
  return static_cast<int>(parties_.size()) - 1;
}

void MujocoJointPhysics::leave_lockstep(int party) {
  {
    std::lock_guard lock(mutex_);
    parties_.at(static_cast<std::size_t>(party)).waited_for = false;
  }
  party_moved_.notify_all();
}

void MujocoJointPhysics::reach(int party, Nanos now) {
  std::unique_lock lock(mutex_);
  Party& self = parties_.at(static_cast<std::size_t>(party));
  self.time = std::max(self.time, now);
  self.waited_for = true;
  step_towards(now);
  party_moved_.notify_all();
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::nanoseconds(lockstep_wait_);
  while (slowest_party() < now) {
    if (party_moved_.wait_until(lock, give_up) == std::cv_status::timeout &&
        slowest_party() < now) {
      for (Party& p : parties_) {
        if (p.time < now) p.waited_for = false;
      }
      ++waits_timed_out_;
    }
  }
  step_towards(now);
}

void MujocoJointPhysics::step() {
  mj_step(model_.get(), data_.get());
  ++steps_;
  if (!torso_history_.empty()) torso_history_[steps_ % kTorsoHistory] = measure_torso();
  const bool fallen = has_fallen(meta_, data_.get(), standing_z_);
  if (fallen && !fallen_) {
    if (falls_ == 0) first_fall_s_ = static_cast<double>(steps_) * model_->opt.timestep;
    ++falls_;
  }
  fallen_ = fallen;
  const double t = static_cast<double>(steps_) * model_->opt.timestep;
  const double x = data_->xpos[3 * meta_.torso_body];
  int requested = kRequested;
  if (start_mark_.compare_exchange_strong(requested, kRecorded)) {
    motion_x0_ = x;
    motion_t0_ = t;
  }
  requested = kRequested;
  if (end_mark_.compare_exchange_strong(requested, kRecorded)) {
    motion_x1_ = x;
    motion_t1_ = t;
  }
  if (feet_ && start_mark_ == kRecorded && end_mark_ != kRecorded) feet_->step(data_.get(), t);
}

void MujocoJointPhysics::measure_feet(double stride_frequency_hz) {
  std::lock_guard lock(mutex_);
  feet_.emplace(meta_, model_->opt.timestep, stride_frequency_hz);
}

void MujocoJointPhysics::mark_motion_start() {
  int none = kNone;
  start_mark_.compare_exchange_strong(none, kRequested);
}

void MujocoJointPhysics::mark_motion_end() {
  int none = kNone;
  end_mark_.compare_exchange_strong(none, kRequested);
}

void MujocoJointPhysics::command(int index, double goal_rad, bool torque_on) {
  std::lock_guard lock(mutex_);
  const auto a = static_cast<std::size_t>(actuator_.at(static_cast<std::size_t>(index)));
  mjModel* m = model_.get();
  // A position actuator's force is gain * ctrl + bias1 * q + bias2 * qdot:
  // all three at zero leave the joint limp.
  m->actuator_gainprm[a * mjNGAIN] = torque_on ? gain_[a] : 0.0;
  m->actuator_biasprm[a * mjNBIAS + 1] = torque_on ? bias1_[a] : 0.0;
  m->actuator_biasprm[a * mjNBIAS + 2] = torque_on ? bias2_[a] : 0.0;
  data_->ctrl[a] = goal_rad;
}

double MujocoJointPhysics::position(int index) const {
  std::lock_guard lock(mutex_);
  const auto a = static_cast<std::size_t>(actuator_.at(static_cast<std::size_t>(index)));
  return data_->qpos[meta_.actuator_qpos[a]];
}

double MujocoJointPhysics::velocity(int index) const {
  std::lock_guard lock(mutex_);
  const auto a = static_cast<std::size_t>(actuator_.at(static_cast<std::size_t>(index)));
  return data_->qvel[meta_.actuator_dof[a]];
}

PhysicsMeasures MujocoJointPhysics::measures() const {
  std::lock_guard lock(mutex_);
  PhysicsMeasures out;
  out.model_file = meta_.file;
  out.timestep_s = model_->opt.timestep;
  out.steps = steps_;
  out.simulated_s = static_cast<double>(steps_) * model_->opt.timestep;
  const int torso = meta_.torso_body;
  out.forward_m = data_->xpos[3 * torso] - x0_;
  out.sideways_m = data_->xpos[3 * torso + 1] - y0_;
  if (start_mark_ == kRecorded) {
    // Not ended yet (or no step since the end mark): up to now.
    const bool ended = end_mark_ == kRecorded;
    out.motion_s = (ended ? motion_t1_ : out.simulated_s) - motion_t0_;
    out.motion_forward_m = (ended ? motion_x1_ : data_->xpos[3 * torso]) - motion_x0_;
  }
  out.falls = falls_;
  out.first_fall_s = first_fall_s_;
  out.fallen = fallen_;
  out.lockstep_waits_timed_out = waits_timed_out_;
  if (feet_) {
    out.stride_length_m = feet_->stride_length_m();
    out.duty_factor = feet_->duty_factor();
  }
  return out;
}

TorsoPose MujocoJointPhysics::torso_pose() const {
  std::lock_guard lock(mutex_);
  const int torso = meta_.torso_body;
  const double dx = data_->xpos[3 * torso] - x0_, dy = data_->xpos[3 * torso + 1] - y0_;
  const double c = std::cos(yaw0_), s = std::sin(yaw0_);
  TorsoPose pose;
  pose.x_m = c * dx + s * dy;
  pose.y_m = -s * dx + c * dy;
  pose.yaw_rad = std::remainder(
      std::atan2(data_->xmat[9 * torso + 3], data_->xmat[9 * torso]) - yaw0_, 2.0 * M_PI);
  pose.time_s = data_->time;
  return pose;
}

TorsoMotion MujocoJointPhysics::torso_motion() const {
  std::lock_guard lock(mutex_);
  return measure_torso();
}

void MujocoJointPhysics::keep_torso_history() {
  std::lock_guard lock(mutex_);
  if (torso_history_.empty()) torso_history_.resize(kTorsoHistory);
}

TorsoMotion MujocoJointPhysics::torso_motion_at(double t_s) const {
  std::unique_lock lock(mutex_);
  const double dt = model_->opt.timestep;
  const auto step = static_cast<std::uint64_t>(std::max(0.0, std::floor(t_s / dt + 1e-9)));
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::nanoseconds(lockstep_wait_);
  while (steps_ < step) {
    if (party_moved_.wait_until(lock, give_up) == std::cv_status::timeout) break;
  }
  if (torso_history_.empty() || step == 0 || steps_ < step || steps_ - step >= kTorsoHistory) {
    return measure_torso();
  }
  return torso_history_[step % kTorsoHistory];
}

TorsoMotion MujocoJointPhysics::measure_torso() const {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  const int torso = meta_.torso_body;
  TorsoMotion out;
  for (int i = 0; i < 4; ++i) out.quat[static_cast<std::size_t>(i)] = d->xquat[4 * torso + i];
  // Body accelerations are filled only for models with acceleration
  // sensors; computing them changes no state the next step reads.
  mj_rnePostConstraint(m, d);
  mjtNum vel[6], acc[6];  // rotational, then translational; in the body's frame
  mj_objectVelocity(m, d, mjOBJ_BODY, torso, vel, 1);
  mj_objectAcceleration(m, d, mjOBJ_BODY, torso, acc, 1);
  for (std::size_t i = 0; i < 3; ++i) {
    out.rate_rad_s[i] = vel[i];
    out.accel_m_s2[i] = acc[3 + i];
  }
  out.time_s = d->time;
  return out;
}

}  // namespace animrt::sim
