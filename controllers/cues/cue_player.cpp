#include "animrt/controllers/cues/cue_player.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/controllers/show/show_audio.hpp"

namespace animrt {
namespace {

// 6x^5 - 15x^4 + 10x^3: from 0 to 1 with zero slope and curvature at both ends.
double smootherstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (x * (6.0 * x - 15.0) + 10.0);
}
// Its largest slope (at x = 1/2) and largest curvature (at x = (3 - sqrt 3) / 6).
constexpr double kPeakSlope = 1.875;
constexpr double kPeakCurvature = 5.773502691896258;  // 10 / sqrt(3)
// The step over which a motion's velocity at its start is estimated.
constexpr double kVelocityStepS = 0.01;

}  // namespace

CuePlayer::CuePlayer(std::vector<Cue> cues, int idle, std::vector<JointSpec> joints,
                     CueRequests& requests)
    : cues_(std::move(cues)), idle_(idle), joints_(std::move(joints)), requests_(requests) {
  if (idle_ < 0 || static_cast<std::size_t>(idle_) >= cues_.size()) {
    throw std::invalid_argument("cue player: the idle cue is not one of the cues");
  }
  std::vector<bool> driven(joints_.size(), false);
  for (const Cue& cue : cues_) {
    if (cue.steps.empty()) throw std::invalid_argument("cue " + cue.name + ": no steps");
    for (const CueStep& step : cue.steps) {
      for (int j : step.source->driven_joints()) {
        if (j >= 0 && static_cast<std::size_t>(j) < driven.size()) driven[j] = true;
      }
    }
  }
  for (std::size_t j = 0; j < driven.size(); ++j) {
    if (driven[j]) driven_.push_back(static_cast<int>(j));
  }
  starts_ = std::make_unique<std::atomic<std::uint64_t>[]>(cues_.size());
  for (Layer& layer : layers_) layer.pose.assign(joints_.size(), 0.0);
  out_.assign(joints_.size(), 0.0);
  prev_out_.assign(joints_.size(), 0.0);
  scratch_.assign(joints_.size(), 0.0);
  // One worker for every learned transition, its models read once each. It
  // holds an in-between for each layer that can play one, and one more
  // being computed; each up to four times the cue's crossfade in frames
  // (the crossfade is lengthened for a far start; a longer one crossfades).
  std::vector<TransitionWorker::Model> models;
  int dims = 0, capacity = 0;
  for (const Cue& cue : cues_) {
    int index = -1;
    if (cue.transition.learned()) {
      for (std::size_t m = 0; m < models.size(); ++m) {
        if (models[m].file == cue.transition.model) index = static_cast<int>(m);
      }
      if (index < 0) {
        index = static_cast<int>(models.size());
        models.push_back({cue.transition.model, cue.transition.model_file});
      }
      dims = std::max(dims, static_cast<int>(cue.transition.joints.size()));
      capacity = std::max(
          capacity,
          static_cast<int>(std::lround(4.0 * cue.crossfade_s / cue.transition.frame_s)) + 1);
    }
    model_of_cue_.push_back(index);
  }
  if (!models.empty()) {
    worker_ = std::make_unique<TransitionWorker>(models, dims, std::max(capacity, 64),
                                                 static_cast<int>(kMaxLayers) + 1);
  }
}

CuePlayer::~CuePlayer() = default;

std::uint64_t CuePlayer::starts(int cue) const {
  if (cue < 0 || static_cast<std::size_t>(cue) >= cues_.size()) return 0;
  return starts_[static_cast<std::size_t>(cue)].load(std::memory_order_relaxed);
}

void CuePlayer::play_sound(const std::string& show_file, ShowAudioPlayer& player) {
  const int index = static_cast<int>(sounds_.size());
  Sound sound;
  sound.player = &player;
  sounds_.push_back(sound);
  for (Cue& cue : cues_) {
    for (CueStep& step : cue.steps) {
      if (step.show_file == show_file) step.sound = index;
    }
  }
}

void CuePlayer::start(const MotionClock& clock) {
  clock_start_ = clock.start;
  lockstep_ = clock.lockstep;
  for (Cue& cue : cues_) {
    for (CueStep& step : cue.steps) step.source->start(clock);
  }
}

void CuePlayer::stop() {
  for (Cue& cue : cues_) {
    for (CueStep& step : cue.steps) step.source->stop();
  }
}

void CuePlayer::steer(const MotionCommand& command) {
  for (Cue& cue : cues_) {
    for (CueStep& step : cue.steps) step.source->steer(command);
  }
}

void CuePlayer::sense(const Sensors& sensors) {
  for (Cue& cue : cues_) {
    for (CueStep& step : cue.steps) step.source->sense(sensors);
  }
}

const CueStep& CuePlayer::step_of(const Layer& layer) const {
  return cues_[static_cast<std::size_t>(layer.cue)].steps[static_cast<std::size_t>(layer.step)];
}

double CuePlayer::weight(const Layer& layer) const {
  if (layer.fade_s <= 0.0) return 1.0;
  return smootherstep((play_ - layer.fade_start) / layer.fade_s);
}

void CuePlayer::sample_layer(Layer& layer) const {
  for (std::size_t j = 0; j < joints_.size(); ++j) layer.pose[j] = joints_[j].home;
  step_of(layer).source->sample(play_ - layer.t0, layer.pose);
}

// The crossfade's length: the cue's, or longer where the gap between the
// present targets and the next motion's start (in position, and in velocity)
// would ask a joint for more than its share of its limits.
double CuePlayer::ease_in_time(const Cue& cue, const MotionSource& next, double at_s) const {
  std::vector<double>& at0 = layers_[count_].pose;  // the slot the layer will take
  for (std::size_t j = 0; j < joints_.size(); ++j) at0[j] = scratch_[j] = joints_[j].home;
  next.sample(at_s, at0);
  next.sample(at_s + kVelocityStepS, scratch_);
  double fade = cue.crossfade_s;
  for (int index : driven_) {
    const auto j = static_cast<std::size_t>(index);
    const double a = kCrossfadeLimitShare * joints_[j].limits.max_acceleration;
    const double v = kCrossfadeLimitShare * joints_[j].limits.max_velocity;
    const double gap = std::abs(at0[j] - out_[j]);
    const double now_v = last_dt_ > 0.0 ? (out_[j] - prev_out_[j]) / last_dt_ : 0.0;
    const double dv = std::abs((scratch_[j] - at0[j]) / kVelocityStepS - now_v);
    if (a > 0.0) {
      fade = std::max({fade, std::sqrt(kPeakCurvature * gap / a), 2.0 * kPeakSlope * dv / a});
    }
    if (v > 0.0) fade = std::max(fade, kPeakSlope * gap / v);
  }
  return fade;
}

void CuePlayer::locate(int cue, double at_s, int& step, double& within) const {
  const Cue& c = cues_[static_cast<std::size_t>(cue)];
  double total = 0.0;
  for (const CueStep& s : c.steps) total += s.duration_s;
  // A looping cue that always ends: its passes repeat.
  if (c.loop && std::isfinite(total) && total > 0.0) at_s = std::fmod(at_s, total);
  step = 0;
  within = at_s > 0.0 ? at_s : 0.0;
  while (static_cast<std::size_t>(step) + 1 < c.steps.size() &&
         within >= c.steps[static_cast<std::size_t>(step)].duration_s) {
    within -= c.steps[static_cast<std::size_t>(step)].duration_s;
    ++step;
  }
  // Past a cue that ends: its last step's end (it hands over at once).
  within = std::min(within, c.steps[static_cast<std::size_t>(step)].duration_s);
}

void CuePlayer::push(int cue, int step, bool asked, double at_s, double fade) const {
  const bool changes = asked || count_ == 0 || layers_[count_ - 1].cue != cue;
  const Cue& c = cues_[static_cast<std::size_t>(cue)];
  if (fade < 0.0) {
    fade =
        count_ == 0 ? 0.0 : ease_in_time(c, *c.steps[static_cast<std::size_t>(step)].source, at_s);
  }
  Layer& layer = layers_[count_];
  layer.cue = cue;
  layer.step = step;
  layer.t0 = play_ - at_s;
  layer.fade_start = play_;
  layer.fade_s = fade;
  layer.learned = -1;
  ++count_;
  if ((step == 0 || asked) && changes) starts_[static_cast<std::size_t>(cue)].fetch_add(1);
  current_.store(cue, std::memory_order_relaxed);
  last_fade_.store(fade, std::memory_order_relaxed);
  switch_sound(c.steps[static_cast<std::size_t>(step)].sound, at_s);
}

// A command to a sound's player, at this cycle's motion time.
void CuePlayer::send_sound(int sound, bool playing, bool seek, double at_s) const {
  Sound& s = sounds_[static_cast<std::size_t>(sound)];
  if (seek) {
    ++s.seeks;
    s.follower.reset();  // a new start owes nothing to the last one's drift
  }
  s.playing = playing;
  if (s.player->control(ShowCommand{playing, s.seeks, at_s}, last_t_)) {
    ++s.sent;
  } else {
    sound_lost_.fetch_add(1, std::memory_order_relaxed);
  }
}

// The newest step's sound starts from the time into it; the one before is cut.
void CuePlayer::switch_sound(int sound, double at_s) const {
  if (sounding_ >= 0 && sounding_ != sound) send_sound(sounding_, false, false, 0.0);
  sounding_ = sound;
  if (sound >= 0) send_sound(sound, !sound_held_, true, at_s);
}

// The motion eases to a halt over kPauseRampS, covering half of it in play
// time: the sound stops halfway, where the motion comes to rest, and plays
// again halfway through the easing back, so the two never part by more
// than the easing's lag (about 40 ms).
void CuePlayer::pause_sound() const {
  const bool held = rate_phase_ < 0.5;
  if (held == sound_held_) return;
  sound_held_ = held;
  if (sounding_ >= 0) send_sound(sounding_, !held, false, 0.0);
}

// The newest step runs on its sound's clock while the sound plays at full
// speed: the gap between the time heard and the step's own time becomes a
// small change of the step's speed (as a show's under `animrt run`).
void CuePlayer::chase_sound() const {
  if (sounding_ < 0 || count_ == 0) return;
  Sound& s = sounds_[static_cast<std::size_t>(sounding_)];
  Layer& top = layers_[count_ - 1];
  const Nanos now = clock_start_ + from_seconds(last_t_);
  SoundClock::Reading r;
  const bool valid = s.playing && rate_phase_ >= 1.0 && s.player->sound_clock().read(r) &&
                     r.playing && r.commands == s.sent &&
                     std::abs(to_seconds(now - r.stamp)) < SoundFollower::kStaleS;
  const double gap = valid ? r.show_s + to_seconds(now - r.stamp) - (play_ - top.t0) : 0.0;
  top.t0 -= s.follower.correction(gap, step_dt_, valid);
}

// Layers under one fully faded in are no longer seen: dropped (their pose
// buffers are kept for later layers, so nothing allocates).
void CuePlayer::compact() const {
  std::size_t base = 0;
  for (std::size_t i = count_; i-- > 1;) {
    if (weight(layers_[i]) >= 1.0) {
      base = i;
      break;
    }
  }
  if (base == 0) return;
  for (std::size_t i = base; i < count_; ++i) std::swap(layers_[i - base], layers_[i]);
  count_ -= base;
}

// A pause slows the play time to a halt and a resume speeds it up again,
// both smoothly. A wind-down keeps the goal it began with.
void CuePlayer::warp(double t) const {
  const double dt = std::max(0.0, t - last_t_);
  last_t_ = t;
  step_dt_ = dt;
  const double goal = winding_ ? wind_goal_ : requests_.paused() ? 0.0 : 1.0;
  const double ease = dt / ease_s_;
  rate_phase_ =
      goal > rate_phase_ ? std::min(goal, rate_phase_ + ease) : std::max(goal, rate_phase_ - ease);
  play_ += smootherstep(rate_phase_) * dt;
  pause_sound();
  // A cue waiting to start at a time into it (a timecode) goes on running.
  if (waiting_ && waiting_at_ > 0.0) waiting_at_ += smootherstep(rate_phase_) * dt;
}

// Every motion still seen winds down on its own time (a crossfade's two
// together: the stop waits for the slower). A source two layers share (a
// cue looping into itself) is asked once, on the newest layer's time.
double CuePlayer::wind_down(double t, double granted_s) {
  if (!begun_ || winding_ || !(granted_s > 0.0)) return 0.0;
  warp(t);
  winding_ = true;
  wind_goal_ = requests_.paused() ? 0.0 : 1.0;
  // A pausing cue comes to rest by itself when its easing ends (0: it
  // stands), sooner when the stop grants less time.
  if (wind_goal_ == 0.0) {
    ease_s_ = std::min(kPauseRampS, granted_s / std::max(rate_phase_, 1e-9));
    return rate_phase_ * ease_s_;
  }
  // The wind-down is in play time; a resume still easing in lags behind by
  // less than what is left of its easing, which the sources' time leaves.
  const double lag = (1.0 - rate_phase_) * ease_s_;
  const double granted_play = granted_s - lag;
  if (!(granted_play > 0.0)) return 0.0;
  double longest = 0.0;
  for (std::size_t i = count_; i-- > 0;) {
    MotionSource* source = step_of(layers_[i]).source.get();
    bool seen = false;
    for (std::size_t k = i + 1; k < count_; ++k) seen |= step_of(layers_[k]).source.get() == source;
    if (!seen) {
      longest = std::max(longest, source->wind_down(play_ - layers_[i].t0, granted_play));
    }
  }
  return longest > 0.0 ? longest + lag : 0.0;
}

void CuePlayer::enter(int cue, int step, bool asked, double at_s) const {
  const bool changes = asked || count_ == 0 || layers_[count_ - 1].cue != cue;
  if (!worker_ || count_ == 0 || !changes || model_of_cue_[static_cast<std::size_t>(cue)] < 0) {
    pending_.active = false;
    push(cue, step, asked, at_s);
    return;
  }
  // A newer request replaces one still being computed, but the figure
  // answers within the bound of the first.
  if (!pending_.active) {
    pending_.deadline = last_t_ + kLearnedWaitS;
    pending_.wall_deadline =
        std::chrono::steady_clock::now() +
        std::chrono::nanoseconds(static_cast<std::int64_t>(kLockstepLearnedWaitS * 1e9));
  }
  pending_.active = true;
  pending_.cue = cue;
  pending_.step = step;
  pending_.asked = asked;
  pending_.within = at_s;
  pending_.posted = false;
  settle();
}

void CuePlayer::settle() const {
  Pending& p = pending_;
  const Cue& c = cues_[static_cast<std::size_t>(p.cue)];
  const CueTransition& tr = c.transition;
  const MotionSource& next = *c.steps[static_cast<std::size_t>(p.step)].source;
  const auto left = [&p] {
    return std::max(std::chrono::nanoseconds(0),
                    std::chrono::duration_cast<std::chrono::nanoseconds>(
                        p.wall_deadline - std::chrono::steady_clock::now()));
  };
  // The worker may still be busy with a request since replaced.
  if (!p.posted && lockstep_) worker_->wait(0, left());
  if (!p.posted && worker_->idle()) {
    // The crossfade's time (lengthened as usual), whole frames of the model's
    // (stretched a little so the last lands on the crossfade's end).
    p.fade = ease_in_time(c, next, p.within);
    p.frames = static_cast<int>(std::lround(p.fade / tr.frame_s));
    // A buffer no layer plays from (there is always one: a layer each, and one more).
    for (p.buffer = 0; p.buffer + 1 < worker_->buffers(); ++p.buffer) {
      bool used = false;
      for (std::size_t i = 0; i < count_; ++i) used |= layers_[i].learned == p.buffer;
      if (!used) break;
    }
    if (p.frames < 2 || p.frames + 1 > worker_->capacity()) {
      learned_unusable_.fetch_add(1, std::memory_order_relaxed);
      p.active = false;
      push(p.cue, p.step, p.asked, p.within, p.fade);
      return;
    }
    // From the present targets to the next motion where the crossfade ends.
    std::vector<double>& at_end = layers_[count_].pose;  // the slot the layer will take
    for (std::size_t j = 0; j < joints_.size(); ++j) at_end[j] = joints_[j].home;
    next.sample(p.within + p.fade, at_end);
    const std::span<double> from = worker_->from();
    const std::span<double> to = worker_->to();
    for (std::size_t m = 0; m < tr.joints.size(); ++m) {
      from[m] = out_[static_cast<std::size_t>(tr.joints[m])];
      to[m] = at_end[static_cast<std::size_t>(tr.joints[m])];
    }
    p.job = worker_->post(model_of_cue_[static_cast<std::size_t>(p.cue)], p.frames, p.buffer);
    p.posted = true;
  }
  if (p.posted && lockstep_) worker_->wait(p.job, left());
  if (p.posted && worker_->finished(p.job)) {
    p.active = false;
    if (!worker_->ok(p.buffer)) {
      learned_unusable_.fetch_add(1, std::memory_order_relaxed);
      push(p.cue, p.step, p.asked, p.within, p.fade);
      return;
    }
    push(p.cue, p.step, p.asked, p.within, p.fade);
    Layer& layer = layers_[count_ - 1];
    layer.learned = p.buffer;
    layer.frames = p.frames;
    learned_played_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  // Not ready in time: the crossfade (its result, when it comes, is dropped).
  if (lockstep_ ? left().count() == 0 : last_t_ >= p.deadline) {
    learned_late_.fetch_add(1, std::memory_order_relaxed);
    p.active = false;
    push(p.cue, p.step, p.asked, p.within);
  }
}

// The targets of a learned transition: the crossfade, eased over to the
// model's frames (a cubic through them, neighbours' slopes) in the first
// quarter and back in the last, with a weight whose first and second
// derivatives vanish at both ends: at the seams the played motion is the
// crossfade's, which joins the old and the new motion without a step; in
// between it is the model's in-between.
void CuePlayer::apply_learned(Layer& layer) const {
  const double s = (play_ - layer.fade_start) / layer.fade_s;
  if (!(s < 1.0)) {
    layer.learned = -1;
    return;
  }
  const double h = smootherstep(std::min(s, 1.0 - s) / kLearnedEaseShare);
  if (h <= 0.0) return;
  const CueTransition& tr = cues_[static_cast<std::size_t>(layer.cue)].transition;
  const int n = layer.frames;
  const double x = std::max(0.0, s) * n;
  const int i = std::min(static_cast<int>(x), n - 1);
  const double u = x - i;
  const double u2 = u * u, u3 = u2 * u;
  const TransitionWorker& w = *worker_;
  for (std::size_t m = 0; m < tr.joints.size(); ++m) {
    const int d = static_cast<int>(m);
    const double v0 = w.frame(layer.learned, i, d);
    const double v1 = w.frame(layer.learned, i + 1, d);
    const double m0 = i > 0 ? (v1 - w.frame(layer.learned, i - 1, d)) / 2.0 : v1 - v0;
    const double m1 = i + 1 < n ? (w.frame(layer.learned, i + 2, d) - v0) / 2.0 : v1 - v0;
    const auto j = static_cast<std::size_t>(tr.joints[m]);
    const double at = std::clamp((2 * u3 - 3 * u2 + 1) * v0 + (u3 - 2 * u2 + u) * m0 +
                                     (-2 * u3 + 3 * u2) * v1 + (u3 - u2) * m1,
                                 joints_[j].limits.min_position, joints_[j].limits.max_position);
    out_[j] += h * (at - out_[j]);
  }
}

void CuePlayer::advance(double t) const {
  if (!begun_) {
    begun_ = true;
    last_t_ = t;
    // Every sound is silent until its step is taken.
    for (std::size_t s = 0; s < sounds_.size(); ++s)
      send_sound(static_cast<int>(s), false, false, 0.0);
    push(idle_, 0, false);
  }
  warp(t);
  // Winding down at a stop: what plays goes on to rest, nothing new starts
  // (an in-between still being computed is given up).
  if (winding_) {
    pending_.active = false;
    return;
  }
  int asked = 0;
  double at = 0.0;
  if (requests_.take(asked, at) && asked >= 0 && static_cast<std::size_t>(asked) < cues_.size()) {
    waiting_ = true;
    waiting_cue_ = asked;
    waiting_at_ = at;
  }
  compact();
  if (waiting_) {
    if (count_ < kMaxLayers) {
      int step = 0;
      double within = 0.0;
      locate(waiting_cue_, waiting_at_, step, within);
      waiting_ = false;
      enter(waiting_cue_, step, true, within);
    } else {
      deferred_.fetch_add(1, std::memory_order_relaxed);
    }
    return;
  }
  // While an in-between is computed the figure plays on what it plays.
  if (pending_.active) {
    settle();
    return;
  }
  const Layer& top = layers_[count_ - 1];
  const Cue& cue = cues_[static_cast<std::size_t>(top.cue)];
  if (play_ - top.t0 < cue.steps[static_cast<std::size_t>(top.step)].duration_s) return;
  if (count_ >= kMaxLayers) return;  // the next step waits for a free slot
  if (static_cast<std::size_t>(top.step) + 1 < cue.steps.size()) {
    push(top.cue, top.step + 1, false);
  } else if (cue.loop || top.cue == idle_) {
    push(top.cue, 0, false);
  } else {
    enter(cue.then < 0 ? idle_ : cue.then, 0, false, 0.0);
  }
}

void CuePlayer::sample(double t, std::span<double> targets) const {
  advance(t);
  chase_sound();
  for (std::size_t i = 0; i < count_; ++i) sample_layer(layers_[i]);
  std::swap(prev_out_, out_);
  std::copy(layers_[0].pose.begin(), layers_[0].pose.end(), out_.begin());
  if (layers_[0].learned >= 0) apply_learned(layers_[0]);
  for (std::size_t i = 1; i < count_; ++i) {
    const double w = weight(layers_[i]);
    for (int j : driven_) {
      const auto k = static_cast<std::size_t>(j);
      out_[k] += w * (layers_[i].pose[k] - out_[k]);
    }
    if (layers_[i].learned >= 0) apply_learned(layers_[i]);
  }
  last_dt_ = step_dt_;
  for (int j : driven_) {
    const auto k = static_cast<std::size_t>(j);
    if (k < targets.size()) targets[k] = out_[k];
  }
}

}  // namespace animrt
