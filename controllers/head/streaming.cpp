// The streaming pipeline: resample -> pitch/energy -> gap fill -> deltas ->
// fixed-lag Viterbi -> key poses -> SQUAD -> noise.

#include "animrt/controllers/head/streaming.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "animrt/controllers/head/spline.hpp"
#include "animrt/controllers/head/squad.hpp"
#include "animrt/controllers/head/synthesis.hpp"

namespace animrt::head {

struct StreamingSynthesizer::Impl {
  const HeadModel& model;
  StreamOptions options;
  SRC_STATE* src = nullptr;
  double ratio = 1.0;
  std::vector<float> resampled;
  PitchEnergyTracker tracker;
  std::vector<RawFrame> raw;
  std::uint64_t pushed = 0;

  // Gap fill.
  long raw_index = 0;
  std::vector<std::pair<long, double>> pending;  // index, energy of unvoiced frames
  std::deque<std::pair<double, double>> knots;   // (index, f0)
  int max_gap = 0;
  double default_f0 = 0;

  // Deltas: base rows (f0, energy) from frame base_offset on.
  std::deque<Eigen::Vector2d> base;
  long base_offset = 0;
  long base_count = 0;    // filled frames so far
  long next_feature = 0;  // next frame to complete
  int w = 2;
  bool finished = false;

  NetworkDecoder decoder;
  long committed = 0;           // clusters committed
  std::deque<double> energies;  // raw energy per frame, from energy_offset
  long energy_offset = 0;

  // Keys and output.
  std::vector<Eigen::Quaterniond> keys;  // sign-consistent, all so far
  long next_out = 0;
  double t0 = 0, fr = 120;

  Impl(const HeadModel& m, StreamOptions o)
      : model(m),
        options(o),
        tracker(m.features),
        decoder(m.hmms, m.bigram, m.decode,
                static_cast<int>(std::lround(o.decoder_lag_s * m.features.frame_rate_hz))) {
    max_gap = static_cast<int>(std::lround(o.max_gap_s * m.features.frame_rate_hz));
    default_f0 = m.feature_mean(0);
    w = m.features.delta_window;
    t0 = m.features.first_frame_time_s();
    fr = m.features.frame_rate_hz;
    if (o.input_rate != m.features.sample_rate) {
      int err = 0;
      src = src_new(SRC_SINC_FASTEST, 1, &err);
      if (src == nullptr)
        throw std::runtime_error(std::string("libsamplerate: ") + src_strerror(err));
      ratio = static_cast<double>(m.features.sample_rate) / o.input_rate;
    }
  }
  ~Impl() {
    if (src) src_delete(src);
  }

  double base_at(long i, int col) const {
    i = std::clamp<long>(i, 0, base_count - 1);
    return base[static_cast<std::size_t>(i - base_offset)](col);
  }
  double d1_at(long i, int col) const {
    // Clamped like the offline deltas: indices outside [0, n-1] replicate the edge.
    double s = 0, norm = 0;
    for (int k = 1; k <= w; ++k) {
      s += k * (base_at(i + k, col) - base_at(i - k, col));
      norm += 2.0 * k * k;
    }
    return s * fr / norm;
  }

  void release(long index, double f0, double energy, std::vector<StreamPose>& out) {
    (void)index;
    base.push_back(Eigen::Vector2d(f0_semitones(f0), energy_db(energy)));
    ++base_count;
    complete_features(out);
  }

  void complete_features(std::vector<StreamPose>& out) {
    // Frame j needs base frames up to j + 2w (or the end of the stream).
    while (next_feature < base_count && (finished || next_feature + 2 * w < base_count)) {
      const long j = next_feature;
      Eigen::VectorXd f(kFeatureDim);
      f(0) = base_at(j, 0);
      f(1) = base_at(j, 1);
      f(2) = d1_at(j, 0);
      f(3) = d1_at(j, 1);
      double norm = 0;
      for (int k = 1; k <= w; ++k) norm += 2.0 * k * k;
      for (int col = 0; col < 2; ++col) {
        double s = 0;
        for (int k = 1; k <= w; ++k) {
          s += k * (d1_at(std::min(j + k, base_count - 1), col) - d1_at(std::max(j - k, 0L), col));
        }
        f(4 + col) = s * fr / norm;
      }
      const Eigen::VectorXd obs = (f - model.feature_mean).cwiseQuotient(model.feature_std);
      int cluster = 0;
      if (decoder.push(obs, cluster)) on_cluster(cluster, out);
      ++next_feature;
      // Keep what the derivatives of later frames still need.
      while (base_offset < next_feature - 2 * w - 1 && base.size() > 1) {
        base.pop_front();
        ++base_offset;
      }
    }
  }

  // Causal smoothing: every output sample whose frame is committed, moved
  // towards the newest cluster's pose by two one-pole slerps.
  Eigen::Quaterniond lp1 = Eigen::Quaterniond::Identity(), lp2 = Eigen::Quaterniond::Identity();
  bool primed = false;

  void on_cluster_causal(int cluster, std::vector<StreamPose>& out) {
    const long frame = committed++;
    const double orate = model.smoothing.output_rate_hz;
    const double alpha = 1.0 - std::exp(-1.0 / (orate * options.causal_time_constant_s));
    const Eigen::Vector3d m = model.cluster_pose(cluster);
    Eigen::Quaterniond q = euler_to_quat({m(0), m(1), m(2)});
    if (!primed) lp1 = lp2 = q;
    primed = true;
    while (std::max(0L, std::lround((static_cast<double>(next_out) / orate - t0) * fr)) <= frame) {
      if (lp1.dot(q) < 0) q.coeffs() = -q.coeffs();
      lp1 = slerp(lp1, q, alpha);
      if (lp2.dot(lp1) < 0) lp2.coeffs() = -lp2.coeffs();
      lp2 = slerp(lp2, lp1, alpha);
      out.push_back(make_pose(lp2));
    }
  }

  StreamPose make_pose(const Eigen::Quaterniond& q) {
    StreamPose p;
    p.t = static_cast<double>(next_out) / model.smoothing.output_rate_hz;
    p.pose = quat_to_euler(q);
    const SmoothingOptions& so = model.smoothing;
    const auto idx = static_cast<std::uint64_t>(next_out);
    p.pose.yaw += pose_noise(so.seed, idx, 0, so.noise_deg);
    p.pose.pitch += pose_noise(so.seed, idx, 1, so.noise_deg);
    p.pose.roll += pose_noise(so.seed, idx, 2, so.noise_deg);
    const long ef = std::clamp<long>(std::lround((p.t - t0) * fr), energy_offset,
                                     energy_offset + static_cast<long>(energies.size()) - 1);
    p.energy = energies.empty() ? 0.0 : energies[static_cast<std::size_t>(ef - energy_offset)];
    ++next_out;
    // Energies older than the output are no longer needed.
    while (energies.size() > 1 && energy_offset < ef - 2) {
      energies.pop_front();
      ++energy_offset;
    }
    return p;
  }

  void on_cluster(int cluster, std::vector<StreamPose>& out) {
    if (options.causal) {
      on_cluster_causal(cluster, out);
      return;
    }
    const long frame = committed++;
    // Key k sits at time k / key_rate: the frame nearest to it.
    const double kr = model.smoothing.key_rate_hz;
    while (true) {
      const long k = static_cast<long>(keys.size());
      const double key_t = static_cast<double>(k) / kr;
      const long key_frame = std::max(0L, std::lround((key_t - t0) * fr));
      if (key_frame != frame) break;
      const Eigen::Vector3d m = model.cluster_pose(cluster);
      Eigen::Quaterniond q = euler_to_quat({m(0), m(1), m(2)});
      if (!keys.empty() && keys.back().dot(q) < 0) q.coeffs() = -q.coeffs();
      keys.push_back(q);
    }
    emit(out, false);
  }

  // Emits output samples whose SQUAD segment is fully known.
  void emit(std::vector<StreamPose>& out, bool final) {
    const double kr = model.smoothing.key_rate_hz;
    const double orate = model.smoothing.output_rate_hz;
    const double end_t = t0 + static_cast<double>(committed - 1) / fr;
    while (true) {
      const double t = static_cast<double>(next_out) / orate;
      const double u = t * kr;
      const auto k = static_cast<long>(std::floor(u));
      const long n = static_cast<long>(keys.size());
      if (final) {
        if (t > end_t || n == 0) break;
      } else if (k + 2 >= n) {
        break;
      }
      auto key = [&](long i) { return keys[static_cast<std::size_t>(std::clamp(i, 0L, n - 1))]; };
      Eigen::Quaterniond q;
      if (k >= n - 1) {
        q = keys.back();
      } else {
        const Eigen::Quaterniond s1 = squad_inner(key(k - 1), key(k), key(k + 1));
        const Eigen::Quaterniond s2 = squad_inner(key(k), key(k + 1), key(k + 2));
        q = squad(key(k), s1, s2, key(k + 1), u - static_cast<double>(k));
      }
      out.push_back(make_pose(q));
    }
  }

  void on_raw(const RawFrame& r, std::vector<StreamPose>& out) {
    const long i = raw_index++;
    energies.push_back(r.energy);
    if (r.voiced) {
      if (!pending.empty()) {
        std::vector<double> x, y;
        for (const auto& k : knots) {
          x.push_back(k.first);
          y.push_back(k.second);
        }
        x.push_back(static_cast<double>(i));
        y.push_back(r.f0_hz);
        const NaturalCubicSpline spline(x, y);
        for (const auto& p : pending) {
          release(p.first,
                  std::clamp(spline(static_cast<double>(p.first)), model.features.f0_min_hz,
                             model.features.f0_max_hz),
                  p.second, out);
        }
        pending.clear();
      }
      release(i, r.f0_hz, r.energy, out);
      knots.push_back({static_cast<double>(i), r.f0_hz});
      while (knots.size() > 3) knots.pop_front();
      return;
    }
    pending.push_back({i, r.energy});
    while (static_cast<int>(pending.size()) > max_gap) release_held(out);
  }

  void release_held(std::vector<StreamPose>& out) {
    const auto p = pending.front();
    pending.erase(pending.begin());
    const double hold = knots.empty() ? default_f0 : knots.back().second;
    release(p.first, hold, p.second, out);
    knots.push_back({static_cast<double>(p.first), hold});
    while (knots.size() > 3) knots.pop_front();
  }
};

StreamingSynthesizer::StreamingSynthesizer(const HeadModel& model, StreamOptions options)
    : impl_(std::make_unique<Impl>(model, options)) {}
StreamingSynthesizer::~StreamingSynthesizer() = default;

void StreamingSynthesizer::push(std::span<const float> block, std::vector<StreamPose>& out) {
  Impl& m = *impl_;
  m.pushed += block.size();
  std::span<const float> samples = block;
  if (m.src != nullptr) {
    m.resampled.resize(static_cast<std::size_t>(static_cast<double>(block.size()) * m.ratio) + 64);
    SRC_DATA d{};
    d.data_in = block.data();
    d.input_frames = static_cast<long>(block.size());
    d.data_out = m.resampled.data();
    d.output_frames = static_cast<long>(m.resampled.size());
    d.src_ratio = m.ratio;
    d.end_of_input = 0;
    const int err = src_process(m.src, &d);
    if (err != 0) throw std::runtime_error(std::string("libsamplerate: ") + src_strerror(err));
    samples =
        std::span<const float>(m.resampled.data(), static_cast<std::size_t>(d.output_frames_gen));
  }
  m.raw.clear();
  m.tracker.push(samples, m.raw);
  for (const RawFrame& r : m.raw) m.on_raw(r, out);
}

void StreamingSynthesizer::finish(std::vector<StreamPose>& out) {
  Impl& m = *impl_;
  while (!m.pending.empty()) m.release_held(out);
  m.finished = true;
  m.complete_features(out);
  std::vector<int> rest;
  m.decoder.finish(rest);
  for (int c : rest) m.on_cluster(c, out);
  if (!m.options.causal) m.emit(out, true);
}

double StreamingSynthesizer::audio_time_s() const {
  return static_cast<double>(impl_->pushed) / impl_->options.input_rate;
}

double StreamingSynthesizer::worst_case_latency_s() const {
  const Impl& m = *impl_;
  const FeatureConfig& f = m.model.features;
  // The sinc resampler (when the input rate differs) delays by a few ms.
  return (m.src != nullptr ? 0.01 : 0.0) + f.window_s / 2 + m.options.max_gap_s +
         2.0 * f.delta_window / f.frame_rate_hz + m.options.decoder_lag_s +
         // Causal: an output sample shows the nearest frame, up to a frame later.
         (m.options.causal ? 1.0 / f.frame_rate_hz : 2.0 / m.model.smoothing.key_rate_hz);
}

}  // namespace animrt::head
