#pragma once
// `animrt run ROBOT --herd SCENE --agent NAME`: the robot is one agent of a
// herd. The herd steps on its own thread on the run's clock and posts the
// agent's speed and turn to the robot's gait through the run's steering
// mailbox; with physics, the MuJoCo torso's measured pose replaces the
// agent's own, so the herd sees the real walk.

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "animrt/controllers/herd/herd.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/run_controls.hpp"
#include "animrt/sim/mujoco/mujoco_physics.hpp"

namespace animrt::cli {

class EmbodiedHerd {
 public:
  // Throws InputError for a bad scene or an agent the scene does not have.
  EmbodiedHerd(const std::string& scene_file, const std::string& agent, const Clock& clock,
               RunControls& controls, const sim::MujocoJointPhysics* physics);
  ~EmbodiedHerd();

  // The motion started at t0 on the run's clock: the herd starts stepping.
  void start(Nanos t0);
  // Stops the herd thread (idempotent).
  void stop();
  // What the herd and the agent did, one line each.
  std::string report() const;

 private:
  void loop();
  void step_until_quit();

  std::unique_ptr<herd::Herd> herd_;
  int agent_ = -1;
  const Clock& clock_;
  RunControls& controls_;
  const sim::MujocoJointPhysics* physics_;
  herd::Vec2 spawn_;
  double spawn_heading_ = 0.0;
  std::atomic<Nanos> t0_{-1};
  std::atomic<bool> quit_{false};
  std::string failure_;  // why the herd stopped the run ("" if it did not); read after stop()
  std::thread thread_;
};

}  // namespace animrt::cli
