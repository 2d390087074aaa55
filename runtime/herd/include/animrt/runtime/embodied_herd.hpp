#pragma once
// A running figure as one agent of a herd (`animrt run ROBOT --herd SCENE
// --agent NAME`): a supervisor outside the cycle. The herd steps on its own
// thread on the run's clock and posts the agent's speed and turn to the
// robot's gait through the run's steering mailbox; given the figure's
// measured track (physics), that replaces the agent's own pose, so the herd
// sees the real walk.

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "animrt/controllers/herd/herd.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/runtime/run_controls.hpp"

namespace animrt {

// The gait a herd figure walks: the motion file of the robot file
// `robot_file`. Throws InputError when that robot's motion is not a gait.
std::string gait_of_robot(const std::string& robot_file);

class EmbodiedHerd {
 public:
  // Where the figure's trunk has gone since its start pose: forward,
  // leftward (m) and turned (rad, counter-clockwise).
  struct Track {
    double x_m = 0.0;
    double y_m = 0.0;
    double yaw_rad = 0.0;
  };
  // Reads the track from the herd's thread; empty when nothing measures it
  // (the agent then walks as its gait achieves).
  using MeasuredTrack = std::function<Track()>;

  // Throws InputError for a bad scene or an agent the scene does not have.
  EmbodiedHerd(const std::string& scene_file, const std::string& agent, const Clock& clock,
               RunControls& controls, MeasuredTrack measured = {});
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
  MeasuredTrack measured_;
  herd::Vec2 spawn_;
  double spawn_heading_ = 0.0;
  std::atomic<Nanos> t0_{-1};
  std::atomic<bool> quit_{false};
  std::string failure_;  // why the herd stopped the run ("" if it did not); read after stop()
  std::thread thread_;
};

}  // namespace animrt
