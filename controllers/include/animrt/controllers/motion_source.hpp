#pragma once
// A motion source turns time into joint targets. sample() runs inside the
// real-time cycle: it must not allocate, lock, log or do I/O. It reads only
// the time it is given, never a clock of its own, so a lockstep run plays
// the same motion however fast the machine is.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animrt/core/clock.hpp"
#include "animrt/core/imu.hpp"

namespace animrt {

class SoundClock;  // controllers/show/sound_clock.hpp

// What a steered source is told while it plays: a herd's or a dashboard's
// command for a walking figure. Sources that cannot be steered ignore it.
struct MotionCommand {
  double speed_m_s = 0.0;   // forward speed
  double turn_rad_s = 0.0;  // turn rate, positive to the left
};

// A keyframe show's transport (a dashboard's play, pause and seek), handed
// over by the cycle like a steering command. Each command states the whole
// transport, so one that replaces another not yet taken loses nothing: the
// playing state, and the latest seek (a seek count the source has not seen
// yet moves the show to t_s first). Sources without a show ignore it.
struct ShowCommand {
  bool playing = true;
  std::uint32_t seeks = 0;  // seeks so far; a new count is a seek to t_s
  double t_s = 0.0;         // the latest seek's show time (clamped to the show)
};

// Where a show's playhead is. `show` is false for a source that plays none.
struct ShowPosition {
  bool show = false;
  bool playing = false;     // its time advances (false: paused, or past a non-looping end)
  double position_s = 0.0;  // time into the show, within [0, duration_s]
  double duration_s = 0.0;
};

// What the figure senses this cycle, handed to a source before sample().
struct Sensors {
  // The trunk's IMU (the robot file's first), null when the figure has none
  // or its reading is stale.
  const ImuReading* imu = nullptr;
  // The joints' measured positions (rad, or m), indexed by robot joint; empty
  // when not known. A joint whose bus was late keeps its last measurement.
  std::span<const double> positions;
};

// The run's clock, handed to a source when its motion starts: CLOCK_MONOTONIC
// in a real-time run, the simulated clock in a lockstep run.
struct MotionClock {
  const Clock* clock = nullptr;
  Nanos start = 0;        // the motion's t = 0 on that clock
  bool lockstep = false;  // the clock moves only when the run steps it
};

class MotionSource {
 public:
  virtual ~MotionSource() = default;

  // Robot joint indices this source drives, fixed after construction.
  virtual std::span<const int> driven_joints() const = 0;

  // Writes targets (rad, or m for a prismatic joint) for the driven joints
  // into `targets`, which is indexed by robot joint index and has one entry
  // per robot joint. Entries of joints it does not drive are left untouched.
  // `t` is seconds since the motion started (t = 0 is the pose the start
  // ramp goes to).
  virtual void sample(double t, std::span<double> targets) const = 0;

  // The newest steering command, handed over by the cycle before sample()
  // when one arrived (the cycle reads it from a lock-free mailbox). Same
  // rules as sample(): no allocation, lock, log or I/O.
  virtual void steer(const MotionCommand& /*command*/) {}

  // This cycle's sensor readings, handed over by the cycle before sample()
  // in the motion phase (a gait's balance reflex reads the trunk's
  // attitude). Same rules as sample(); the pointers live for this call only.
  virtual void sense(const Sensors& /*sensors*/) {}

  // A stop was asked for at motion time `t` (a stop request or the end of
  // the run's duration; never a fault, which ramps home at once): a source
  // that must come to rest by itself before its joints go home (a walk
  // that winds down while it keeps stepping, so the body slows instead of
  // being stopped dead) begins to, and returns how long that takes (s).
  // `granted_s` is the most the stop deadline leaves for it: a source
  // comes fully to rest within it (a shorter wind-down, never a cut one)
  // and returns at most that. The cycle samples it that long, then ramps
  // home. 0: ramp home at once (a motion with nothing to wind down). Same
  // rules as sample().
  virtual double wind_down(double /*t*/, double /*granted_s*/) { return 0.0; }

  // A show's transport: a source that plays a show keeps its own playhead,
  // which maps the motion's time `t` (as sample() gets it) to the show's.
  // control() acts at motion time `t` (the cycle's, before sample()): a seek
  // moves the show's time, a pause holds it, a play lets it advance again
  // (a non-looping show that has ended plays again from its start). Same
  // rules as sample().
  virtual void control(const ShowCommand& /*command*/, double /*t*/) {}
  virtual ShowPosition show_position(double /*t*/) const { return {}; }

  // The motion starts (called by the cycle's shell right after the cycle
  // that sampled t = 0; same rules as sample()). A source whose work runs
  // outside the cycle (a head's speech stream on a worker thread) paces that
  // work on this clock and on no other, so that in a lockstep run it follows
  // the simulated time; there sample(t) may wait until the work due by the
  // clock's time is done, as the run waits for a lockstep bus. A source
  // plays in one run.
  virtual void start(const MotionClock& /*clock*/) {}

  // The sound track of the show file `show_file` plays on `clock`: a source
  // that plays that show follows the sound's time from now on (called before
  // the run, outside the cycle). Others ignore it.
  virtual void follow_sound(const std::string& /*show_file*/, const SoundClock& /*clock*/) {}

  // The run is over (called outside the cycle, on every way out of the run):
  // the clock handed to start() is read no more, it may be gone.
  virtual void stop() {}
};

}  // namespace animrt
