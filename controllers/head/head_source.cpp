// The head MotionSource: a worker thread streams audio through the
// synthesizer as it "arrives" on the run's clock and publishes poses into a
// preallocated ring; sample() only reads the ring (no allocation, no lock,
// no I/O; in lockstep it waits for the blocks due by the run's clock).

#include "animrt/controllers/head/head_source.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "animrt/controllers/head/alsa_audio.hpp"
#include "animrt/controllers/head/streaming.hpp"
#include "animrt/core/error.hpp"

namespace animrt::head {
namespace {

constexpr Nanos kNever = std::numeric_limits<Nanos>::max();

struct Drive {
  int joint = -1;
  double gain = 1.0, offset_deg = 0.0, lo = 0.0, hi = 0.0;  // lo/hi in rad
};

class HeadSource final : public MotionSource {
 public:
  HeadSource(const HeadMotionConfig& c, HeadModel model, Audio audio, Drive axes[3], Drive jaw,
             HeadJawMap jaw_map)
      : config_(c),
        model_(std::move(model)),
        audio_(std::move(audio)),
        jaw_(jaw),
        jaw_map_(std::move(jaw_map)) {
    for (int i = 0; i < 3; ++i) axes_[i] = axes[i];
    for (const Drive& d : axes_) {
      if (d.joint >= 0) driven_.push_back(d.joint);
    }
    if (jaw_.joint >= 0) driven_.push_back(jaw_.joint);
    StreamOptions so;
    so.input_rate = audio_.sample_rate;
    so.decoder_lag_s = c.decoder_lag_s;
    so.max_gap_s = c.max_gap_s;
    stream_options_ = so;
    block_ = std::max<std::size_t>(1, static_cast<std::size_t>(c.block_s * audio_.sample_rate));
    // One cycle: the utterance, then the pause.
    if (c.capture.empty()) {
      cycle_ = audio_.samples;
      cycle_.resize(cycle_.size() + static_cast<std::size_t>(c.pause_s * audio_.sample_rate), 0.0f);
    }
    {
      StreamingSynthesizer probe(model_, so);
      latency_s_ = probe.worst_case_latency_s() + c.block_s;
    }
    rate_ = model_.smoothing.output_rate_hz;
    if (c.precomputed) {
      StreamingSynthesizer s(model_, so);
      std::vector<StreamPose> out;
      for (std::size_t i = 0; i < cycle_.size(); i += block_) {
        s.push(std::span<const float>(cycle_.data() + i, std::min(block_, cycle_.size() - i)), out);
      }
      s.finish(out);
      ring_ = std::vector<Slot>(out.size());
      for (std::size_t i = 0; i < out.size(); ++i) store(i, out[i]);
      written_.store(out.size());
    } else {
      ring_ = std::vector<Slot>(static_cast<std::size_t>(rate_ * 60.0));
      worker_ = std::thread([this] { run(); });
    }
  }

  ~HeadSource() override { stop(); }

  std::span<const int> driven_joints() const override { return driven_; }

  void start(const MotionClock& clock) override {
    if (clock.clock == nullptr || started_.load(std::memory_order_relaxed)) return;
    clock_ = clock;
    // Live capture follows the microphone, whatever the run's clock.
    waits_ = clock.lockstep && worker_.joinable() && config_.capture.empty();
    started_.store(true, std::memory_order_release);
  }

  void stop() override {
    stop_.store(true);
    if (worker_.joinable()) worker_.join();
  }

  void sample(double t, std::span<double> targets) const override {
    if (waits_) await_stream();
    double pose[4] = {0, 0, 0, 0};  // yaw, pitch, roll, energy
    const double audio_t = t - latency_s_;
    const std::uint64_t written = written_.load(std::memory_order_acquire);
    if (audio_t >= 0 && written > 0) {
      std::uint64_t idx = static_cast<std::uint64_t>(audio_t * rate_);
      if (config_.precomputed) {
        idx = config_.repeat ? idx % written : std::min<std::uint64_t>(idx, written - 1);
      } else {
        idx =
            std::min<std::uint64_t>(idx, written - 1);  // the stream is late: hold the newest pose
      }
      const Slot& s = ring_[static_cast<std::size_t>(idx % ring_.size())];
      for (int k = 0; k < 4; ++k) pose[k] = s.v[k].load(std::memory_order_relaxed);
    }
    for (int k = 0; k < 3; ++k) {
      const Drive& d = axes_[k];
      if (d.joint < 0 || static_cast<std::size_t>(d.joint) >= targets.size()) continue;
      targets[static_cast<std::size_t>(d.joint)] =
          std::clamp(deg_to_rad(d.gain * pose[k] + d.offset_deg), d.lo, d.hi);
    }
    if (jaw_.joint >= 0 && static_cast<std::size_t>(jaw_.joint) < targets.size()) {
      const double open = std::clamp(
          (pose[3] - jaw_map_.energy_floor) / (jaw_map_.energy_full - jaw_map_.energy_floor), 0.0,
          1.0);
      const double deg = jaw_map_.closed_deg + open * (jaw_map_.open_deg - jaw_map_.closed_deg);
      targets[static_cast<std::size_t>(jaw_.joint)] = std::clamp(deg_to_rad(deg), jaw_.lo, jaw_.hi);
    }
  }

 private:
  struct Slot {
    std::atomic<double> v[4];
  };

  // Lockstep: every block due by the run's clock is in the ring before a
  // pose is read, so the pose depends on the simulated time alone. The
  // worker ends with seen_ = kNever, so this never outwaits it.
  void await_stream() const {
    const Nanos now = clock_.clock->now();
    for (int spins = 0; seen_.load(std::memory_order_acquire) < now; ++spins) {
      if (spins < 64) {
        std::this_thread::yield();
      } else {
        std::this_thread::sleep_for(std::chrono::microseconds(20));
      }
    }
  }

  // Until the run's clock reaches `due`; false when stopping. A lockstep
  // clock moves only when the run steps it: while it stands, every block
  // due by it has been fed, which seen_ tells sample().
  bool wait_until(Nanos due) {
    for (;;) {
      if (stop_.load()) return false;
      const Nanos now = clock_.clock->now();
      if (now >= due) return true;
      if (clock_.lockstep) {
        seen_.store(now, std::memory_order_release);
        std::this_thread::sleep_for(std::chrono::microseconds(50));
      } else {
        std::this_thread::sleep_for(std::chrono::nanoseconds(due - now));
      }
    }
  }

  void store(std::size_t i, const StreamPose& p) {
    Slot& s = ring_[i % ring_.size()];
    s.v[0].store(p.pose.yaw, std::memory_order_relaxed);
    s.v[1].store(p.pose.pitch, std::memory_order_relaxed);
    s.v[2].store(p.pose.roll, std::memory_order_relaxed);
    s.v[3].store(p.energy, std::memory_order_relaxed);
  }

  // Worker: waits for the motion to start, then feeds one block per block
  // period of the run's clock (audio "arrives" as the motion's time passes),
  // playing it to ALSA when asked.
  void run() {
    struct Done {
      std::atomic<Nanos>& seen;
      ~Done() { seen.store(kNever, std::memory_order_release); }
    } done{seen_};
    while (!stop_.load() && !started_.load(std::memory_order_acquire)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (stop_.load()) return;
    std::unique_ptr<AlsaPlayback> playback;
    std::unique_ptr<AlsaCapture> capture;
    try {
      if (!config_.capture.empty())
        capture = std::make_unique<AlsaCapture>(config_.capture, audio_.sample_rate);
      if (config_.audio_device != "none" && config_.capture.empty()) {
        const std::string dev = config_.audio_device == "auto" ? "default" : config_.audio_device;
        if (config_.audio_device != "auto" || alsa_playback_available(dev)) {
          playback = std::make_unique<AlsaPlayback>(dev, audio_.sample_rate);
          // Delay the sound by the synthesis latency so head and voice match.
          std::vector<float> lead(static_cast<std::size_t>(latency_s_ * audio_.sample_rate), 0.0f);
          playback->write(lead);
        }
      }
    } catch (const std::exception&) {
      return;  // no device: the head stays at rest (the run still works)
    }
    StreamingSynthesizer stream(model_, stream_options_);
    std::vector<StreamPose> out;
    std::vector<float> block(block_);
    const Nanos start = clock_.start;
    std::uint64_t fed = 0, next = 0;
    std::size_t pos = 0;
    while (!stop_.load()) {
      if (capture) {
        capture->read(block);
      } else {
        if (pos >= cycle_.size()) {
          if (!config_.repeat) break;
          pos = 0;
        }
        const std::size_t n = std::min(block_, cycle_.size() - pos);
        std::copy_n(cycle_.begin() + static_cast<std::ptrdiff_t>(pos), n, block.begin());
        std::fill(block.begin() + static_cast<std::ptrdiff_t>(n), block.end(), 0.0f);
        pos += n;
        // This block has "arrived" once its last sample has been spoken.
        const Nanos due = start + static_cast<Nanos>(static_cast<double>(fed + block_) * 1e9 /
                                                     audio_.sample_rate);
        if (!wait_until(due)) break;
        if (playback) playback->write(block);
      }
      fed += block_;
      out.clear();
      stream.push(block, out);
      for (const StreamPose& p : out) store(static_cast<std::size_t>(next++), p);
      written_.store(next, std::memory_order_release);
    }
    if (!stop_.load()) {
      out.clear();
      stream.finish(out);
      for (const StreamPose& p : out) store(static_cast<std::size_t>(next++), p);
      written_.store(next, std::memory_order_release);
    }
  }

  HeadMotionConfig config_;
  HeadModel model_;
  Audio audio_;
  Drive axes_[3];
  Drive jaw_;
  HeadJawMap jaw_map_;
  std::vector<int> driven_;
  StreamOptions stream_options_;
  std::size_t block_ = 1;
  std::vector<float> cycle_;
  double latency_s_ = 0, rate_ = 120;
  std::vector<Slot> ring_;
  std::atomic<std::uint64_t> written_{0};
  // The run's clock from start() on (written before started_, read by the
  // worker after it); waits_: sample() waits for the stream (lockstep).
  MotionClock clock_;
  bool waits_ = false;
  std::atomic<bool> started_{false};
  std::atomic<Nanos> seen_{0};  // lockstep: the clock time every due block is fed by
  std::atomic<bool> stop_{false};
  std::thread worker_;
};

Drive bind_joint(const std::string& name, const Location& where, const std::string& key,
                 std::span<const JointSpec> joints) {
  Drive d;
  if (name.empty()) return d;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].name == name) {
      d.joint = static_cast<int>(i);
      d.lo = joints[i].limits.min_position;
      d.hi = joints[i].limits.max_position;
    }
  }
  if (d.joint < 0) {
    std::string have;
    for (const auto& j : joints) have += (have.empty() ? "" : ", ") + j.name;
    throw InputError(
        where, key, "no joint named '" + elide(name) + "' in the robot (its joints: " + have + ")");
  }
  return d;
}

}  // namespace

std::unique_ptr<MotionSource> make_head_source(const HeadMotionConfig& c,
                                               std::span<const JointSpec> joints) {
  HeadModel model = load_model(c.model);
  if (c.noise_deg) model.smoothing.noise_deg = *c.noise_deg;
  Audio audio;
  if (!c.audio.empty()) {
    audio = load_audio(c.audio);
  } else {
    audio.sample_rate = model.features.sample_rate;
  }
  Drive axes[3];
  const HeadAxisMap* maps[3] = {&c.yaw, &c.pitch, &c.roll};
  const char* keys[3] = {"motion.axes.yaw.joint", "motion.axes.pitch.joint",
                         "motion.axes.roll.joint"};
  for (int k = 0; k < 3; ++k) {
    axes[k] = bind_joint(maps[k]->joint, maps[k]->where, keys[k], joints);
    axes[k].gain = maps[k]->sign * maps[k]->scale;
    axes[k].offset_deg = maps[k]->offset_deg;
  }
  const Drive jaw = bind_joint(c.jaw.joint, c.jaw.where, "motion.jaw.joint", joints);
  return std::make_unique<HeadSource>(c, std::move(model), std::move(audio), axes, jaw, c.jaw);
}

}  // namespace animrt::head
