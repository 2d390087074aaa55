// A show bound to a robot's joints, and layers of motion sources.

#include <algorithm>
#include <cmath>
#include <utility>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/controllers/show/show_playhead.hpp"
#include "animrt/controllers/show/sound_clock.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt {
namespace {

class ShowSource final : public MotionSource {
 public:
  struct Track {
    int joint = 0;
    std::vector<ShowKey> keys;
    std::vector<double> slope;  // rad/s at each key (cubic tangents)
  };

  ShowSource(std::vector<Track> tracks, bool loop, double duration, std::string file)
      : tracks_(std::move(tracks)),
        loop_(loop),
        duration_(duration),
        file_(std::move(file)),
        playhead_(duration, loop) {
    for (const Track& t : tracks_) driven_.push_back(t.joint);
  }

  std::span<const int> driven_joints() const override { return driven_; }

  void control(const ShowCommand& command, double t) override {
    playhead_.control(command, t);
    ++commands_;
  }

  ShowPosition show_position(double t) const override { return playhead_.position(t); }

  void follow_sound(const std::string& show_file, const SoundClock& clock) override {
    if (show_file == file_) sound_ = &clock;
  }
  void start(const MotionClock& clock) override { start_ = clock.start; }

  void sample(double t, std::span<double> targets) const override {
    follow(t);
    t = playhead_.time(t);
    if (loop_) {
      t = std::fmod(t, duration_);
      if (t < 0) t += duration_;
    }
    for (const Track& track : tracks_) {
      if (static_cast<std::size_t>(track.joint) < targets.size()) {
        targets[static_cast<std::size_t>(track.joint)] = eval(track, t);
      }
    }
  }

 private:
  double eval(const Track& tr, double t) const {
    const auto& k = tr.keys;
    const std::size_t n = k.size();
    if (n == 1) return k[0].value;
    // Segment [i, i+1); before the first key: hold it (or, looping, the wrap
    // segment from the last key); after the last: hold it or wrap.
    std::size_t i;
    double t0, t1, v0, v1, s0, s1;
    if (t < k[0].t || t >= k[n - 1].t) {
      if (!loop_) return t < k[0].t ? k[0].value : k[n - 1].value;
      i = n - 1;
      t0 = k[n - 1].t;
      t1 = k[0].t + duration_;
      if (t < k[0].t) t += duration_;
      v0 = k[n - 1].value;
      v1 = k[0].value;
      s0 = tr.slope[n - 1];
      s1 = tr.slope[0];
    } else {
      // Last key with k.t <= t (binary search, no allocation).
      i = static_cast<std::size_t>(
              std::upper_bound(k.begin(), k.end(), t,
                               [](double x, const ShowKey& key) { return x < key.t; }) -
              k.begin()) -
          1;
      t0 = k[i].t;
      t1 = k[i + 1].t;
      v0 = k[i].value;
      v1 = k[i + 1].value;
      s0 = tr.slope[i];
      s1 = tr.slope[i + 1];
    }
    const double h = t1 - t0;
    if (!(h > 0)) return v0;
    const double u = (t - t0) / h;
    switch (k[i].interpolation) {
      case Interpolation::step:
        return v0;
      case Interpolation::linear:
        return v0 + (v1 - v0) * u;
      case Interpolation::cubic:
      case Interpolation::learned: {  // learned tracks hold the model's frames as cubic keys
        const double u2 = u * u, u3 = u2 * u;
        return (2 * u3 - 3 * u2 + 1) * v0 + (u3 - 2 * u2 + u) * h * s0 + (-2 * u3 + 3 * u2) * v1 +
               (u3 - u2) * h * s1;
      }
    }
    return v0;
  }

  // With a sound track playing, the show's time is the sound's: the gap
  // between the sound's time (interpolated from the player's newest reading
  // to this cycle) and the playhead's becomes a small change of speed. The
  // loop's clock alone where no sound is followed: none plays, it is
  // paused, stale, or has not yet taken the show's latest command.
  void follow(double t) const {
    if (sound_ == nullptr) return;
    const double dt = t - last_t_;
    if (!(dt > 0.0)) return;  // the same cycle again, or the first
    last_t_ = t;
    const Nanos now = start_ + from_seconds(t);
    SoundClock::Reading r;
    const bool valid = !playhead_.paused() && sound_->read(r) && r.playing &&
                       r.commands == commands_ &&
                       std::abs(to_seconds(now - r.stamp)) < SoundFollower::kStaleS;
    const double gap = valid ? r.show_s + to_seconds(now - r.stamp) - playhead_.time(t) : 0.0;
    playhead_.nudge(follower_.correction(gap, dt, valid));
  }

  std::vector<Track> tracks_;
  bool loop_;
  double duration_;
  std::string file_;
  std::vector<int> driven_;
  mutable ShowPlayhead playhead_;  // nudged by the sound in sample()
  const SoundClock* sound_ = nullptr;
  Nanos start_ = 0;
  std::uint64_t commands_ = 0;  // show commands taken, as the sound's player counts them
  mutable SoundFollower follower_;
  mutable double last_t_ = 0.0;
};

// Slopes for cubic segments: the slope between the neighbours of each key
// (so consecutive cubic segments share it: continuous velocity); zero at the
// ends of a non-looping show; wrapping for a looping one.
std::vector<double> slopes(const std::vector<ShowKey>& k, bool loop, double duration) {
  const std::size_t n = k.size();
  std::vector<double> s(n, 0.0);
  if (n < 2) return s;
  for (std::size_t i = 0; i < n; ++i) {
    double tp, vp, tn, vn;
    if (i > 0) {
      tp = k[i - 1].t;
      vp = k[i - 1].value;
    } else if (loop) {
      tp = k[n - 1].t - duration;
      vp = k[n - 1].value;
    } else {
      continue;
    }
    if (i + 1 < n) {
      tn = k[i + 1].t;
      vn = k[i + 1].value;
    } else if (loop) {
      tn = k[0].t + duration;
      vn = k[0].value;
    } else {
      continue;
    }
    s[i] = tn > tp ? (vn - vp) / (tn - tp) : 0.0;
  }
  return s;
}

// The learned tracks' in-betweens: the model completes every gap between the
// shared key frames (looping: also the wrap back to the first key) and its
// frames become the tracks' keys, played with cubic interpolation like any
// other keys. Frames outside a joint's limits are clamped to them, as the
// safety filter would.
void complete_learned(const ShowFile& show, std::span<const JointSpec> joints,
                      std::vector<ShowSource::Track>& tracks) {
  const ShowLearned& learned = show.learned;
  std::vector<ShowSource::Track*> by_input;  // the tracks in the model's joint order
  for (const std::string& name : learned.joints) {
    for (ShowSource::Track& t : tracks) {
      if (joints[static_cast<std::size_t>(t.joint)].name == name) by_input.push_back(&t);
    }
  }
  const std::vector<ShowKey>& first = by_input.front()->keys;
  const std::size_t key_count = first.size();
  if (key_count < 2) return;  // one key: nothing between
  const std::size_t columns = key_count + (show.loop ? 1 : 0);
  seqnet::FrameMatrix keys(static_cast<Eigen::Index>(by_input.size()),
                           static_cast<Eigen::Index>(columns));
  std::vector<double> times(columns);
  for (std::size_t k = 0; k < columns; ++k) {
    const std::size_t key = k % key_count;
    times[k] = first[key].t + (k < key_count ? 0.0 : show.duration_s);
    for (std::size_t j = 0; j < by_input.size(); ++j) {
      keys(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(k)) =
          by_input[j]->keys[key].value;
    }
  }
  std::vector<int> gaps;
  for (std::size_t k = 0; k + 1 < columns; ++k) {
    gaps.push_back(static_cast<int>(std::lround((times[k + 1] - times[k]) / learned.frame_s)) - 1);
  }
  seqnet::SeqNetInference net(*learned.model, learned.model_file);
  const seqnet::Completion done = net.complete(keys, gaps);
  // Looping: the last column is the first key again, played by the wrap.
  const Eigen::Index frames = done.frames.cols() - (show.loop ? 1 : 0);
  for (std::size_t j = 0; j < by_input.size(); ++j) {
    ShowSource::Track& track = *by_input[j];
    const JointLimits& lim = joints[static_cast<std::size_t>(track.joint)].limits;
    const Location where = track.keys.front().where;
    track.keys.clear();
    for (Eigen::Index f = 0; f < frames; ++f) {
      ShowKey key;
      key.t = times[0] + static_cast<double>(f) * learned.frame_s;
      // Clamping would turn inf into a limit unnoticed; NaN and inf are
      // both the model's fault, refused with the track's line.
      if (const double v = done.frames(static_cast<Eigen::Index>(j), f); !std::isfinite(v)) {
        throw InputError(where, "joints." + joints[static_cast<std::size_t>(track.joint)].name,
                         "the learned model " + quote_path(learned.model_file) + " completed " +
                             (std::isnan(v) ? std::string("nan")
                              : v > 0       ? "inf"
                                            : "-inf") +
                             " at " + format_number(key.t) + " s; a learned track must be finite");
      }
      key.value = std::clamp(done.frames(static_cast<Eigen::Index>(j), f), lim.min_position,
                             lim.max_position);
      key.interpolation = Interpolation::cubic;
      key.where = where;
      track.keys.push_back(key);
    }
  }
}

class LayeredSource final : public MotionSource {
 public:
  explicit LayeredSource(std::vector<std::unique_ptr<MotionSource>> layers)
      : layers_(std::move(layers)) {
    for (const auto& l : layers_) {
      for (int j : l->driven_joints()) {
        if (std::find(driven_.begin(), driven_.end(), j) == driven_.end()) driven_.push_back(j);
      }
    }
  }
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double t, std::span<double> targets) const override {
    for (const auto& l : layers_) l->sample(t, targets);
  }
  void control(const ShowCommand& command, double t) override {
    for (const auto& l : layers_) l->control(command, t);
  }
  // A steered gait under a show's head moves is steered as on its own.
  void steer(const MotionCommand& command) override {
    for (const auto& l : layers_) l->steer(command);
  }
  void sense(const Sensors& sensors) override {
    for (const auto& l : layers_) l->sense(sensors);
  }
  void start(const MotionClock& clock) override {
    for (const auto& l : layers_) l->start(clock);
  }
  // Every layer winds down together (a walk under a show's head moves),
  // each within the time granted: the stop waits for the slowest.
  double wind_down(double t, double granted_s) override {
    double longest = 0.0;
    for (const auto& l : layers_) longest = std::max(longest, l->wind_down(t, granted_s));
    return longest;
  }
  void follow_sound(const std::string& show_file, const SoundClock& clock) override {
    for (const auto& l : layers_) l->follow_sound(show_file, clock);
  }
  void stop() override {
    for (const auto& l : layers_) l->stop();
  }
  // The first show layer's playhead (every show layer gets the same commands).
  ShowPosition show_position(double t) const override {
    for (const auto& l : layers_) {
      const ShowPosition p = l->show_position(t);
      if (p.show) return p;
    }
    return {};
  }

 private:
  std::vector<std::unique_ptr<MotionSource>> layers_;
  std::vector<int> driven_;
};

}  // namespace

std::unique_ptr<MotionSource> make_show_source(const ShowFile& show,
                                               std::span<const JointSpec> joints) {
  std::vector<ShowSource::Track> tracks;
  for (const ShowTrack& st : show.tracks) {
    ShowSource::Track t;
    t.joint = -1;
    std::string names;
    for (std::size_t j = 0; j < joints.size(); ++j) {
      names += (names.empty() ? "" : ", ") + joints[j].name;
      if (joints[j].name == st.joint) t.joint = static_cast<int>(j);
    }
    if (t.joint < 0) {
      throw InputError(
          st.where, "joints." + st.joint,
          "no joint named '" + elide(st.joint) + "' in the robot (its joints: " + names + ")");
    }
    const JointSpec& joint = joints[static_cast<std::size_t>(t.joint)];
    const bool prismatic = joint.type == JointType::prismatic;
    if (st.unit == (prismatic ? ShowUnit::deg : ShowUnit::m)) {
      throw InputError(st.unit_where, "joints." + st.joint + ".unit",
                       prismatic ? "unit deg, but joint '" + elide(st.joint) +
                                       "' is prismatic (its limits are in metres); use unit: m"
                                 : "unit m, but joint '" + elide(st.joint) +
                                       "' is revolute (its limits are in degrees); use unit: deg");
    }
    const char* unit = prismatic ? " m" : " deg";
    auto as_written = [prismatic](double si) { return prismatic ? si : rad_to_deg(si); };
    const JointLimits& lim = joint.limits;
    t.keys = st.keys;
    for (ShowKey& k : t.keys) {
      const double written = k.value;
      k.value = prismatic ? written : deg_to_rad(written);
      if (k.value < lim.min_position - 1e-9 || k.value > lim.max_position + 1e-9) {
        throw InputError(k.where, "joints." + st.joint + ".keys",
                         "key at " + format_number(k.t) + " s is " + format_number(written) + unit +
                             ", outside the joint's limits " +
                             format_number(as_written(lim.min_position)) + ".." +
                             format_number(as_written(lim.max_position)) + unit);
      }
    }
    tracks.push_back(std::move(t));
  }
  if (show.has_learned) complete_learned(show, joints, tracks);
  for (ShowSource::Track& t : tracks) t.slope = slopes(t.keys, show.loop, show.duration_s);
  return std::make_unique<ShowSource>(std::move(tracks), show.loop, show.duration_s, show.file);
}

std::unique_ptr<MotionSource> load_show_source(const std::string& path,
                                               std::span<const JointSpec> joints) {
  return make_show_source(load_show_file(path), joints);
}

std::unique_ptr<MotionSource> make_layered_source(
    std::vector<std::unique_ptr<MotionSource>> layers) {
  return std::make_unique<LayeredSource>(std::move(layers));
}

}  // namespace animrt
