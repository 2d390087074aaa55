#pragma once
// MuJoCo physics behind the simulated servos (`animrt run --physics
// MODEL.xml`): each robot joint is bound by name to the position actuator on
// the model's hinge joint of the same name. A servo's goal becomes its
// actuator's target; torque off makes the actuator limp; present position and
// velocity are the joint's. The physics steps at the model's own timestep,
// as many steps as the clock has moved on since the start, so a lockstep run
// is deterministic.
//
// It also watches the figure: forward (+x) and sideways travel of the torso,
// and falls by the same criterion as the gait fitness (has_fallen: torso
// below half its standing height, tilted more than 60 degrees, the trunk on
// the ground, or unstable).

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "animrt/core/joint.hpp"
#include "animrt/sim/joint_physics.hpp"
#include "animrt/sim/mujoco/foot_meter.hpp"
#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::sim {

// Where the torso is on the ground, relative to where it started: x forward
// and y to the left of its starting heading, yaw counter-clockwise.
struct TorsoPose {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
  double time_s = 0.0;  // physics time
};

struct PhysicsMeasures {
  std::string model_file;
  double timestep_s = 0.0;
  std::uint64_t steps = 0;
  double simulated_s = 0.0;  // steps x timestep, since the start
  double forward_m = 0.0;    // torso's +x displacement since the start
  double sideways_m = 0.0;   // torso's +y displacement since the start
  // The motion proper, between mark_motion_start() and mark_motion_end():
  double motion_s = 0.0;             // physics time between the marks (0: not marked)
  double motion_forward_m = 0.0;     // torso's +x displacement between them
  int falls = 0;                     // times the figure went from upright to fallen
  double first_fall_s = -1.0;        // simulated time of the first fall, -1 if none
  bool fallen = false;               // fallen at the end
  int lockstep_waits_timed_out = 0;  // a bus kept the others waiting past the lockstep wait
  // The feet over the motion, counted as the gait fitness counts them
  // (FootMeter); -1 unless measure_feet() was called.
  double stride_length_m = -1.0;
  double duty_factor = -1.0;
};

// What an IMU on the torso measures: its attitude in the world (w, x, y, z,
// MuJoCo's xquat), its angular velocity and the specific force (what an
// accelerometer feels: +1 g up at rest) in the torso's own frame.
struct TorsoMotion {
  std::array<double, 4> quat{1.0, 0.0, 0.0, 0.0};
  std::array<double, 3> rate_rad_s{};
  std::array<double, 3> accel_m_s2{};
  double time_s = 0.0;  // physics time
};

class MujocoJointPhysics final : public JointPhysics {
 public:
  // Loads `model_path` and binds every joint of `joints` (the robot's, named
  // in `robot_file`). Throws InputError naming the model file and the robot
  // joint for a joint the model has no actuator for (and for an invalid
  // model). The figure starts at rest standing in the joints' home pose, its
  // lowest foot on the floor; actuators of the model that no robot joint
  // drives hold 0 (within their joint's range) throughout. Physics time 0 is
  // `start` on the clock the servos use.
  MujocoJointPhysics(const std::string& model_path, const std::vector<JointSpec>& joints,
                     const std::string& robot_file, Nanos start);
  ~MujocoJointPhysics() override;

  int joint_index(const std::string& joint) const override;
  void advance(Nanos now) override;
  void command(int index, double goal_rad, bool torque_on) override;
  double position(int index) const override;
  double velocity(int index) const override;
  int join_lockstep() override;
  void reach(int party, Nanos now) override;
  void leave_lockstep(int party) override;
  // How long a lockstep party ahead waits for the others (wall time).
  static constexpr Nanos kDefaultLockstepWait = 500'000'000;
  void set_lockstep_wait(Nanos wait) { lockstep_wait_ = wait; }  // before the buses start

  // Marks the start and the end of the motion (after the start ramp, before
  // the stop ramp): the next physics step records the torso's position.
  // Lock-free and allocation-free, so the real-time cycle may call them; in
  // lockstep the next step is the same one in every run.
  void mark_motion_start();
  void mark_motion_end();

  // Counts the feet's contacts over the motion (between the marks) for a
  // gait of this stride frequency, as the gait fitness does; before the
  // motion starts.
  void measure_feet(double stride_frequency_hz);

  PhysicsMeasures measures() const;
  TorsoPose torso_pose() const;
  TorsoMotion torso_motion() const;
  // The torso's motion as it was at physics time `t_s` (the newest step at
  // or before it, from a history of the last kTorsoHistory steps), waiting
  // (wall time, as long as a lockstep party waits) for the physics to get
  // there. A simulated IMU asks for its frame's time this way, so that in
  // lockstep a frame reports the same state whichever thread runs first.
  TorsoMotion torso_motion_at(double t_s) const;
  // Keeps that history from now on (each step then also measures the torso).
  void keep_torso_history();
  static constexpr std::size_t kTorsoHistory = 128;

 private:
  void step();  // one mj_step, the fall watch and the torso's history; mutex held
  TorsoMotion measure_torso() const;  // mutex held
  // Steps on to `now`, never past a lockstep party's time; mutex held.
  void step_towards(Nanos now);
  Nanos slowest_party() const;  // mutex held; the largest Nanos without parties

  MujocoModel meta_;  // names and addresses (shares nothing mutable)
  std::unique_ptr<mjModel, void (*)(mjModel*)> model_;  // own copy: torque off edits its gains
  MujocoData data_;
  std::vector<std::string> names_;            // robot joints, by index
  std::vector<int> actuator_;                 // robot joint index -> actuator
  std::vector<double> gain_, bias1_, bias2_;  // per actuator, as loaded
  Nanos start_;
  Nanos step_ns_;
  double standing_z_ = 0.0;
  double x0_ = 0.0;
  double y0_ = 0.0;
  double yaw0_ = 0.0;

  mutable std::mutex mutex_;
  mutable std::condition_variable party_moved_;
  struct Party {
    Nanos time = 0;
    bool waited_for = true;  // false: left, or passed over after a wait timed out
  };
  std::vector<Party> parties_;
  Nanos lockstep_wait_ = kDefaultLockstepWait;
  int waits_timed_out_ = 0;
  std::uint64_t steps_ = 0;
  std::vector<TorsoMotion> torso_history_;  // by step % kTorsoHistory
  int falls_ = 0;
  double first_fall_s_ = -1.0;
  bool fallen_ = false;
  enum Mark : int { kNone, kRequested, kRecorded };
  std::atomic<int> start_mark_{kNone};
  std::atomic<int> end_mark_{kNone};
  double motion_x0_ = 0.0, motion_t0_ = 0.0;  // recorded at the start mark
  double motion_x1_ = 0.0, motion_t1_ = 0.0;  // recorded at the end mark
  std::optional<FootMeter> feet_;             // with measure_feet()
};

}  // namespace animrt::sim
