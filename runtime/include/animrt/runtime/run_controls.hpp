#pragma once
// How commands from outside the cycle reach it: a signal handler, a
// dashboard or a herd writes here from its own thread; the cycle reads every
// control once, at its start, as part of its inputs. Nothing here blocks
// either side.

#include <atomic>

#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/mailbox.hpp"
#include "animrt/runtime/telemetry.hpp"

namespace animrt {

// Moves one joint away from what the motion asks, by `offset` (rad, or m for
// a prismatic joint), through the same safety filter as every other target.
// A new jog of the same joint replaces the old one; offset 0 ends it.
struct JogCommand {
  int joint = -1;  // robot joint index
  double offset = 0.0;
};

// Manual mode's absolute target for one joint (rad, or m for a prismatic
// joint); clamped to the joint's limits and passed through the safety filter.
struct ManualTarget {
  int joint = -1;  // robot joint index
  double position = 0.0;
};

struct RunControls {
  // Ramp home and end the run (a stop signal, a dashboard's stop).
  std::atomic<bool> stop{false};
  // Switch torque off at once, without a ramp (a second stop signal).
  std::atomic<bool> abort{false};
  // Speed and turn of a steered motion source.
  Mailbox<MotionCommand> steer;
  Mailbox<JogCommand> jog;
  // A show's play, pause or seek (a dashboard's).
  Mailbox<ShowCommand> show;
  // Manual mode (a dashboard's sliders): while on, the motion's targets are
  // replaced by a held pose that starts where the joints are and moves only
  // by manual targets; off returns to the motion through the safety filter.
  std::atomic<bool> manual{false};
  // Manual targets, in order (one writer): a ring, not a mailbox, so that
  // targets for two joints posted within one cycle both arrive. Each record
  // is {joint, position}.
  TelemetryRing manual_targets{2, 256};
};

}  // namespace animrt
