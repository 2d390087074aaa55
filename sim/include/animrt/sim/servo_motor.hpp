#pragma once
// The motor model every simulated serial servo shares when no physics
// drives its joint: speed = clamp(error / tau, +-vmax), integrated in
// closed form, so the result does not depend on how often it is asked.
// Units are the servo's own (ticks or steps, per second).

namespace animrt::sim {

struct ServoMotor {
  double position = 0;
  double velocity = 0;

  // Where the motor is `dt_s` seconds later, following `goal` at most at
  // `vmax` per second with time constant `tau_s` (0: a pure rate limiter).
  ServoMotor after(double dt_s, double goal, double vmax, double tau_s) const;
};

}  // namespace animrt::sim
