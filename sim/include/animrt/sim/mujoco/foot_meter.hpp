#pragma once
// The feet of a walk as the gait fitness counts them: each physics step, which
// feet touch something; from that the duty factor (the fraction of steps each
// foot is down) and the stride length (a foot's advance from its first
// landing to its last, per stride period between them). The fitness walk and
// the runtime's physics count with this one class, so their walks compare.

#include <mujoco/mujoco.h>

#include <vector>

#include "animrt/sim/mujoco/mujoco_model.hpp"

namespace animrt::sim {

class FootMeter {
 public:
  // `stride_frequency_hz`: the gait's, which says what a swing and a stride
  // period are. Allocates here only: step() may run in any loop.
  FootMeter(const MujocoModel& model, double timestep_s, double stride_frequency_hz);

  // One physics step measured, at physics time `t_s`.
  void step(const mjData* d, double t_s);

  long steps() const { return steps_; }
  double duty_factor() const;      // 0 before any step
  double stride_length_m() const;  // 0 without a foot landing twice a stride period apart

 private:
  struct Foot {
    long air_steps = 0;      // since it last touched
    long contact_steps = 0;  // measured steps it touched
    long landings = 0;
    double first_t = 0.0, first_x = 0.0, last_t = 0.0, last_x = 0.0;
  };
  std::vector<int> geoms_;    // foot index -> geom
  std::vector<int> foot_of_;  // geom -> foot index, -1 for others
  std::vector<Foot> feet_;
  std::vector<char> contact_;
  double frequency_hz_;
  long min_swing_steps_;
  long steps_ = 0;
};

}  // namespace animrt::sim
