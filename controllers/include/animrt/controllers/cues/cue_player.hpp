#pragma once
// A figure in service plays cues: an idle cue, and cues that triggers ask
// for (cue_requests.hpp). Each cue is a sequence of steps (a show, a gait, a
// held pose), each played for its time, then the next step, the cue again
// (a loop) or the cue it hands over to. Every change of motion is a
// crossfade: the new motion's targets are blended in with a weight whose
// first and second derivatives are zero at both ends, so the blend adds no
// velocity or acceleration step of its own; a crossfade that would ask a
// joint for more than a share of its velocity or acceleration limit (a cue
// that starts far from the present pose) is lengthened until it does not.
// Joints a step does not drive go to their home pose. A cue asked for at a
// time into it (a timecode that jumped into its middle) starts at that
// time, through the same crossfade.
//
// The player is a motion source: everything it plays is built and allocated
// before the run, and sample() only reads requests and blends.
//
// A step whose show has a sound track plays it (play_sound). The sound
// belongs to the newest cue alone: it starts when its step is taken (at the
// time into it the step starts at) and is cut when another step or cue is
// taken, while the motions crossfade (a voice does not talk over itself). A
// pause holds the sound where the motion comes to rest: halfway through the
// pause's easing, and it resumes halfway through the easing back. While it
// plays, the step's motion runs on the sound's clock (SoundFollower), as a
// show does under `animrt run`.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "animrt/controllers/cues/cue_requests.hpp"
#include "animrt/controllers/cues/transition_worker.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/controllers/show/sound_clock.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {

inline constexpr double kForever = std::numeric_limits<double>::infinity();

class ShowAudioPlayer;  // controllers/show/show_audio.hpp

struct CueStep {
  std::unique_ptr<MotionSource> source;
  double duration_s = kForever;  // kForever: until another cue is asked for
  std::string show_file = {};    // the show it plays, whose sound track it has (empty: none)
  int sound = -1;                // the player's: its sound track, -1 none
};

// How a cue is entered: the crossfade, or (with a model) a learned
// in-between from the present pose to the cue's pose at the crossfade's end.
struct CueTransition {
  std::shared_ptr<const seqnet::ModelFile> model;  // null: the crossfade
  std::string model_file;
  double frame_s = 0.04;    // the model's frame time
  std::vector<int> joints;  // the robot's joint of each model input
  bool learned() const { return model != nullptr; }
};

struct Cue {
  std::string name;
  std::vector<CueStep> steps;
  double crossfade_s = 1.0;  // into this cue, and between its steps
  CueTransition transition;  // into this cue (a trigger or a handover)
  bool loop = false;         // after its last step, its first again
  int then = -1;             // after its last step (not looping): this cue; -1 the idle cue
};

// How playback slows to a pause and speeds up again (the motion's time is
// warped with the same smooth weight, so a pause is no velocity step).
inline constexpr double kPauseRampS = 0.5;
// The share of a joint's velocity and acceleration limits a crossfade may
// use on its own.
inline constexpr double kCrossfadeLimitShare = 0.3;
// How long a learned in-between may take to compute, from the first
// request it answers: then the cue crossfades in instead (counted).
inline constexpr double kLearnedWaitS = 0.1;
// The same on a lockstep clock, in wall time: the figure's time stands while
// the cycle waits, so a machine too loaded to compute the in-between within
// kLearnedWaitS does not change the run; only a model far too slow does.
inline constexpr double kLockstepLearnedWaitS = 2.0;
// The share of a learned transition at each end over which the played
// targets ease from the crossfade to the model's frames and back.
inline constexpr double kLearnedEaseShare = 0.25;

class CuePlayer final : public MotionSource {
 public:
  // `idle` indexes `cues`. `joints` are the robot's (limits and home pose).
  CuePlayer(std::vector<Cue> cues, int idle, std::vector<JointSpec> joints, CueRequests& requests);
  ~CuePlayer() override;

  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override;
  void start(const MotionClock& clock) override;
  void stop() override;
  // Steering and the cycle's sensor readings reach every cue's motion, so a
  // steered or balanced walk has them whenever it plays.
  void steer(const MotionCommand& command) override;
  void sense(const Sensors& sensors) override;
  // At a stop, what plays winds down (a walking cue eases to a stand) and
  // no other cue or step starts; a pause eases to rest instead, and a cue
  // that is paused already asks for nothing.
  double wind_down(double t, double granted_s) override;

  // Read from any thread while it plays.
  int current_cue() const { return current_.load(std::memory_order_relaxed); }
  std::uint64_t starts(int cue) const;  // how often each cue began (asked for, or handed over)
  // Requests taken while every crossfade slot was busy, played when one freed.
  std::uint64_t deferred() const { return deferred_.load(std::memory_order_relaxed); }
  const std::vector<Cue>& cues() const { return cues_; }
  // The crossfade time of the newest change (after any lengthening).
  double last_crossfade_s() const { return last_fade_.load(std::memory_order_relaxed); }

  // Learned transitions: played, fallen back to the crossfade because the
  // in-between was not ready within learned_wait_s(), or because it could
  // not be used (not finite, more frames than planned for).
  std::uint64_t learned_played() const { return learned_played_.load(std::memory_order_relaxed); }
  std::uint64_t learned_late() const { return learned_late_.load(std::memory_order_relaxed); }
  // kLearnedWaitS, or kLockstepLearnedWaitS (wall time) on a lockstep clock.
  double learned_wait_s() const { return lockstep_ ? kLockstepLearnedWaitS : kLearnedWaitS; }
  std::uint64_t learned_unusable() const {
    return learned_unusable_.load(std::memory_order_relaxed);
  }
  // The worker that computes them (null when no cue has one).
  TransitionWorker* transition_worker() const { return worker_.get(); }

  // The steps that play `show_file` sound through `player` (before the run,
  // outside the cycle; the player's origin is the motion's start). It is
  // told from the cycle when to play, and is silent until its step is taken.
  void play_sound(const std::string& show_file, ShowAudioPlayer& player);
  // Sound commands the players could not take (they had fallen behind).
  std::uint64_t sound_commands_lost() const { return sound_lost_.load(std::memory_order_relaxed); }

 private:
  // One motion being blended in; the newest is on top.
  struct Layer {
    int cue = 0;
    int step = 0;
    double t0 = 0.0;          // play time at which the step's source had t = 0
    double fade_start = 0.0;  // play time
    double fade_s = 0.0;
    int learned = -1;  // the in-between's buffer while it plays, -1 none
    int frames = 0;    // its frames after the present pose
    std::vector<double> pose;
  };
  // A learned transition asked for, whose in-between is being computed.
  struct Pending {
    bool active = false;
    int cue = 0, step = 0;
    bool asked = false;
    double within = 0.0;
    bool posted = false;
    std::uint64_t job = 0;
    int buffer = 0;
    int frames = 0;
    double fade = 0.0;
    double deadline = 0.0;                                  // motion time
    std::chrono::steady_clock::time_point wall_deadline{};  // lockstep
  };
  static constexpr std::size_t kMaxLayers = 4;

  void advance(double t) const;
  void warp(double t) const;  // the play time at motion time t
  const CueStep& step_of(const Layer& layer) const;
  // `asked`: a trigger's (a cue asked for again starts again, and counts);
  // `at_s`: the time into the step it starts at.
  void push(int cue, int step, bool asked, double at_s = 0.0, double fade = -1.0) const;
  // A change into `cue`: a learned transition's computation begins, or the
  // crossfade at once.
  void enter(int cue, int step, bool asked, double at_s) const;
  // A pending learned transition: posted, taken when ready, or given up.
  void settle() const;
  void apply_learned(Layer& layer) const;
  // The step of `cue` and the time into it at `at_s` into the cue.
  void locate(int cue, double at_s, int& step, double& within) const;
  double ease_in_time(const Cue& cue, const MotionSource& next, double at_s) const;
  void sample_layer(Layer& layer) const;
  void compact() const;
  double weight(const Layer& layer) const;
  // The sound: the newest step's starts, the one before is cut; a pause holds it.
  void switch_sound(int sound, double at_s) const;
  void send_sound(int sound, bool playing, bool seek, double at_s) const;
  void pause_sound() const;
  void chase_sound() const;

  std::vector<Cue> cues_;
  int idle_;
  std::vector<JointSpec> joints_;
  std::vector<int> driven_;
  CueRequests& requests_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> starts_;
  mutable std::atomic<int> current_{-1};
  mutable std::atomic<std::uint64_t> deferred_{0};
  mutable std::atomic<double> last_fade_{0.0};
  std::unique_ptr<TransitionWorker> worker_;
  std::vector<int> model_of_cue_;  // the worker's model index, -1 crossfade
  // On a lockstep clock (not real time) the cycle waits for an in-between,
  // up to kLockstepLearnedWaitS of wall time, so that a run is repeatable.
  bool lockstep_ = false;
  mutable Pending pending_;
  mutable std::atomic<std::uint64_t> learned_played_{0}, learned_late_{0}, learned_unusable_{0};

  // The playback state: the cycle's alone (sample() is const to its caller).
  mutable std::array<Layer, kMaxLayers> layers_;
  mutable std::size_t count_ = 0;
  mutable bool begun_ = false;
  mutable double last_t_ = 0.0;
  mutable double play_ = 0.0;        // play time: motion time slowed by pauses
  mutable double rate_phase_ = 1.0;  // 1 playing, 0 paused, between: easing
  mutable bool waiting_ = false;     // a request waits for a free slot
  bool winding_ = false;             // a stop's wind-down began: nothing new starts
  double wind_goal_ = 1.0;           // the playback rate's goal while it winds down
  double ease_s_ = kPauseRampS;      // pause/resume easing time (shorter in a granted wind-down)
  mutable int waiting_cue_ = 0;
  mutable double waiting_at_ = 0.0;  // its time into the cue
  mutable std::vector<double> out_, prev_out_, scratch_;
  mutable double last_dt_ = 0.0;  // motion time between prev_out_ and out_
  mutable double step_dt_ = 0.0;  // this call's

  struct Sound {
    ShowAudioPlayer* player = nullptr;
    std::uint64_t sent = 0;  // commands handed over
    std::uint32_t seeks = 0;
    bool playing = false;
    SoundFollower follower;
  };
  mutable std::vector<Sound> sounds_;
  mutable int sounding_ = -1;        // the sound of the newest step, -1 none
  mutable bool sound_held_ = false;  // held by a pause
  Nanos clock_start_ = 0;            // the motion's t = 0 on the run's clock
  mutable std::atomic<std::uint64_t> sound_lost_{0};
};

}  // namespace animrt
