// The head MotionSource: a worker thread streams audio through the
// synthesizer as it "arrives" on the run's clock (or from a live input) and
// publishes poses into a preallocated ring; sample() only reads the ring and
// the immutable sound (no allocation, no lock, no I/O; in lockstep it waits
// for the blocks due by the run's clock). The jaw's energy does not wait for
// the synthesizer: a file's is computed from its samples in sample(), live
// sound's is published per block.

#include "animrt/controllers/head/head_source.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "animrt/controllers/head/alsa_audio.hpp"
#include "animrt/controllers/head/audio_input.hpp"
#include "animrt/controllers/head/streaming.hpp"
#include "animrt/core/error.hpp"

namespace animrt::head {
namespace {

constexpr Nanos kNever = std::numeric_limits<Nanos>::max();

// The jaw's energy: RMS of a window about its mean, from the window's sum
// and sum of squares. A DC offset (a cheap microphone's) or any constant
// signal is no speech and leaves the jaw closed.
double window_rms(double sum, double sum_sq, std::size_t n) {
  const double count = static_cast<double>(n);
  const double mean = sum / count;
  return std::sqrt(std::max(0.0, sum_sq / count - mean * mean));
}

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
    so.causal = c.causal;
    stream_options_ = so;
    block_ = std::max<std::size_t>(1, static_cast<std::size_t>(c.block_s * audio_.sample_rate));
    jaw_window_ = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::lround(jaw_map_.window_s * audio_.sample_rate)));
    live_ = !c.capture.empty() || c.live;
    // One cycle: the utterance, then the pause.
    if (c.capture.empty()) {
      cycle_ = audio_.samples;
      cycle_.resize(cycle_.size() + static_cast<std::size_t>(c.pause_s * audio_.sample_rate), 0.0f);
    }
    {
      StreamingSynthesizer probe(model_, so);
      latency_s_ = probe.worst_case_latency_s() + c.block_s;
    }
    // A file is looked ahead by the latency (whole blocks); live sound is not.
    pose_delay_s_ = live_ ? latency_s_ : 0.0;
    lead_blocks_ = live_ ? 0
                         : static_cast<std::uint64_t>(std::ceil(latency_s_ * audio_.sample_rate /
                                                                static_cast<double>(block_)));
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
    // Live capture follows its device, whatever the run's clock.
    waits_ = clock.lockstep && worker_.joinable() && config_.capture.empty();
    started_.store(true, std::memory_order_release);
  }

  void stop() override {
    stop_.store(true);
    if (worker_.joinable()) worker_.join();
  }

  void sample(double t, std::span<double> targets) const override {
    if (waits_) await_stream();
    double pose[3] = {0, 0, 0};  // yaw, pitch, roll
    const double audio_t = t - pose_delay_s_;
    const std::uint64_t written = written_.load(std::memory_order_acquire);
    if (audio_t >= 0 && written > 0) {
      std::uint64_t idx = static_cast<std::uint64_t>(audio_t * rate_);
      if (config_.precomputed) {
        idx = config_.repeat ? idx % written : std::min<std::uint64_t>(idx, written - 1);
      } else if (live_) {
        idx = written - 1;  // live: the newest final pose, whatever the motion's time
      } else {
        idx =
            std::min<std::uint64_t>(idx, written - 1);  // the stream is late: hold the newest pose
      }
      const Slot& s = ring_[static_cast<std::size_t>(idx % ring_.size())];
      for (int k = 0; k < 3; ++k) pose[k] = s.v[k].load(std::memory_order_relaxed);
    }
    for (int k = 0; k < 3; ++k) {
      const Drive& d = axes_[k];
      if (d.joint < 0 || static_cast<std::size_t>(d.joint) >= targets.size()) continue;
      targets[static_cast<std::size_t>(d.joint)] =
          std::clamp(deg_to_rad(d.gain * pose[k] + d.offset_deg), d.lo, d.hi);
    }
    if (jaw_.joint >= 0 && static_cast<std::size_t>(jaw_.joint) < targets.size()) {
      const double energy = live_ ? live_energy_.load(std::memory_order_acquire) : file_energy(t);
      const double open = std::clamp(
          (energy - jaw_map_.energy_floor) / (jaw_map_.energy_full - jaw_map_.energy_floor), 0.0,
          1.0);
      const double deg = jaw_map_.closed_deg + open * (jaw_map_.open_deg - jaw_map_.closed_deg);
      targets[static_cast<std::size_t>(jaw_.joint)] = std::clamp(deg_to_rad(deg), jaw_.lo, jaw_.hi);
    }
  }

 private:
  struct Slot {
    std::atomic<double> v[3];
  };

  // Sample i of the sound as it plays (the cycle repeated, or silence after
  // its end); the sound's sample i is heard at motion time i / rate.
  float stream_sample(std::int64_t i) const {
    if (i < 0 || cycle_.empty()) return 0.0f;
    const auto n = static_cast<std::int64_t>(cycle_.size());
    if (i >= n && !config_.repeat) return 0.0f;
    return cycle_[static_cast<std::size_t>(i % n)];
  }

  // RMS of the sound's samples heard by motion time t (the window ends at
  // the newest one), so the jaw never leads the sound.
  double file_energy(double t) const {
    const auto last = static_cast<std::int64_t>(std::floor(t * audio_.sample_rate));
    double sum = 0.0, sum_sq = 0.0;
    for (std::size_t k = 0; k < jaw_window_; ++k) {
      const double v = stream_sample(last - static_cast<std::int64_t>(k));
      sum += v;
      sum_sq += v * v;
    }
    return window_rms(sum, sum_sq, jaw_window_);
  }

  // Fills `block` with the stream's block j; false past the end of a sound
  // that does not repeat.
  bool stream_block(std::uint64_t j, std::span<float> block) const {
    const auto first = static_cast<std::int64_t>(j * block_);
    if (!config_.repeat && first >= static_cast<std::int64_t>(cycle_.size())) return false;
    for (std::size_t k = 0; k < block.size(); ++k)
      block[k] = stream_sample(first + static_cast<std::int64_t>(k));
    return true;
  }

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
  }

  // The jaw's path for live sound: the RMS of the newest jaw window of
  // samples, published as soon as a block has arrived.
  void publish_energy(std::span<const float> block) {
    for (const float v : block) {
      recent_[recent_at_] = v;
      recent_at_ = (recent_at_ + 1) % recent_.size();
    }
    double sum = 0.0, sum_sq = 0.0;
    for (const float v : recent_) {
      sum += v;
      sum_sq += static_cast<double>(v) * v;
    }
    live_energy_.store(window_rms(sum, sum_sq, recent_.size()), std::memory_order_release);
  }

  // Reader thread (live input): each block's energy for the jaw, then the
  // block into a ring for the synthesizer; a synthesizer that has fallen a
  // ring behind loses blocks (counted) rather than hold the jaw up.
  void read_live(AudioInput& input) {
    std::vector<float> block(block_);
    while (!stop_.load()) {
      if (!input.read(block)) break;
      publish_energy(block);
      const std::uint64_t w = captured_written_.load(std::memory_order_relaxed);
      if (w - captured_read_.load(std::memory_order_acquire) >= kCapturedBlocks) {
        captured_lost_.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      std::copy(block.begin(), block.end(),
                captured_.begin() + static_cast<std::ptrdiff_t>((w % kCapturedBlocks) * block_));
      captured_written_.store(w + 1, std::memory_order_release);
    }
    input_ended_.store(true, std::memory_order_release);
  }

  // Synthesizer side of the ring: the next captured block; false when the
  // input has ended (or the run stops) and the ring is empty.
  bool take_captured(std::span<float> block) {
    for (;;) {
      const std::uint64_t r = captured_read_.load(std::memory_order_relaxed);
      if (captured_written_.load(std::memory_order_acquire) > r) {
        const auto from =
            captured_.begin() + static_cast<std::ptrdiff_t>((r % kCapturedBlocks) * block_);
        std::copy(from, from + static_cast<std::ptrdiff_t>(block_), block.begin());
        captured_read_.store(r + 1, std::memory_order_release);
        return true;
      }
      if (stop_.load() || input_ended_.load(std::memory_order_acquire)) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  // Opens the live input, or ALSA playback of a file; false when a device
  // cannot be opened (the head then stays at rest; the run still works).
  bool open_devices(std::unique_ptr<AudioInput>& input, std::unique_ptr<AlsaPlayback>& playback) {
    try {
      if (!config_.capture.empty())
        input = open_audio_input(config_.capture, audio_.sample_rate, &stop_);
      if (config_.audio_device != "none" && config_.capture.empty()) {
        const std::string dev = config_.audio_device == "auto" ? "default" : config_.audio_device;
        if (config_.audio_device != "auto" || alsa_playback_available(dev))
          playback = std::make_unique<AlsaPlayback>(dev, audio_.sample_rate);
      }
    } catch (const std::exception&) {
      return false;
    }
    return true;
  }

  // Worker: waits for the motion to start, then feeds the synthesizer. A
  // live input paces it; a file's block j "arrives" once its last sample
  // has been spoken on the run's clock, and is fed lead_blocks_ earlier.
  void run() {
    struct Done {
      std::atomic<Nanos>& seen;
      ~Done() { seen.store(kNever, std::memory_order_release); }
    } done{seen_};
    while (!stop_.load() && !started_.load(std::memory_order_acquire)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (stop_.load()) return;
    std::unique_ptr<AudioInput> input;
    std::unique_ptr<AlsaPlayback> playback;
    if (!open_devices(input, playback)) return;
    recent_.assign(jaw_window_, 0.0f);
    if (input) {
      // The jaw's path: its own thread reads the device and publishes each
      // block's energy at once, whatever the synthesizer below is doing.
      captured_.assign(kCapturedBlocks * block_, 0.0f);
      reader_ = std::thread([this, in = input.get()] { read_live(*in); });
    }
    StreamingSynthesizer stream(model_, stream_options_);
    std::vector<StreamPose> out;
    std::uint64_t next = 0;
    auto feed = [&](std::span<const float> block) {
      if (live_ && !input) publish_energy(block);  // a live input's reader publishes its own
      out.clear();
      stream.push(block, out);
      for (const StreamPose& p : out) store(static_cast<std::size_t>(next++), p);
      written_.store(next, std::memory_order_release);
    };
    std::vector<float> block(block_), heard(block_);
    bool ended = false;
    for (std::uint64_t j = 0; j < lead_blocks_ && !ended; ++j) {
      ended = !stream_block(j, block);
      if (!ended) feed(block);
    }
    const Nanos start = clock_.start;
    for (std::uint64_t j = 0; !ended && !stop_.load(); ++j) {
      if (input) {
        ended = !take_captured(block);
        if (!ended) feed(block);
        continue;
      }
      const Nanos due = start + static_cast<Nanos>(static_cast<double>((j + 1) * block_) * 1e9 /
                                                   audio_.sample_rate);
      if (!wait_until(due)) break;
      if (playback && stream_block(j, heard)) playback->write(heard);
      ended = !stream_block(j + lead_blocks_, block);
      if (!ended) feed(block);
    }
    // The input ended (the reader has ended) or the run stops (it sees stop_).
    if (reader_.joinable()) reader_.join();
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
  std::size_t block_ = 1, jaw_window_ = 1;
  std::vector<float> cycle_;
  bool live_ = false;
  double latency_s_ = 0, pose_delay_s_ = 0, rate_ = 120;
  std::uint64_t lead_blocks_ = 0;
  std::vector<Slot> ring_;
  std::atomic<std::uint64_t> written_{0};
  // Worker only: the newest jaw window of live samples (a ring).
  std::vector<float> recent_;
  std::size_t recent_at_ = 0;
  std::atomic<double> live_energy_{0.0};
  // The run's clock from start() on (written before started_, read by the
  // worker after it); waits_: sample() waits for the stream (lockstep).
  MotionClock clock_;
  bool waits_ = false;
  std::atomic<bool> started_{false};
  // Lockstep: the clock time every due block is fed by (-1: not yet, even
  // the look-ahead at the start).
  std::atomic<Nanos> seen_{-1};
  std::atomic<bool> stop_{false};
  std::thread worker_;
  // Live input: the reader thread and its ring of blocks for the synthesizer.
  static constexpr std::uint64_t kCapturedBlocks = 256;
  std::thread reader_;
  std::vector<float> captured_;
  std::atomic<std::uint64_t> captured_written_{0}, captured_read_{0}, captured_lost_{0};
  std::atomic<bool> input_ended_{false};
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

Audio load_head_audio(const HeadMotionConfig& c) {
  try {
    return load_audio(c.audio);
  } catch (const InputError& e) {
    // The audio's own error names only the WAV; say which file and key chose
    // it (a config built in code has none).
    if (c.audio_where.file.empty()) throw;
    throw InputError(c.audio_where, c.audio_key,
                     "audio file " + quote_path(c.audio) + ": " + e.message());
  }
}

std::unique_ptr<MotionSource> make_head_source(const HeadMotionConfig& c,
                                               std::span<const JointSpec> joints) {
  HeadModel model = load_model(c.model);
  if (c.noise_deg) model.smoothing.noise_deg = *c.noise_deg;
  Audio audio;
  if (!c.audio.empty()) {
    audio = load_head_audio(c);
  } else {
    audio.sample_rate = model.features.sample_rate;
  }
  Drive axes[3];
  const HeadAxisMap* maps[3] = {&c.yaw, &c.pitch, &c.roll};
  for (int k = 0; k < 3; ++k) {
    axes[k] = bind_joint(maps[k]->joint, maps[k]->where, maps[k]->key, joints);
    axes[k].gain = maps[k]->sign * maps[k]->scale;
    axes[k].offset_deg = maps[k]->offset_deg;
  }
  const Drive jaw = bind_joint(c.jaw.joint, c.jaw.where, c.jaw.key, joints);
  return std::make_unique<HeadSource>(c, std::move(model), std::move(audio), axes, jaw, c.jaw);
}

}  // namespace animrt::head
