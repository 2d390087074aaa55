#include "animrt/controllers/head/synthesis.hpp"

#include <algorithm>
#include <cmath>

#include "animrt/controllers/head/squad.hpp"

namespace animrt::head {

double pose_noise(std::uint64_t seed, std::uint64_t index, int axis, double amplitude) {
  if (amplitude <= 0) return 0.0;
  // splitmix64 of (seed, index, axis): stateless, so a stream can produce
  // sample n without replaying samples 0..n-1.
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + index * 3 + static_cast<std::uint64_t>(axis) + 1;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  const double u = static_cast<double>(z >> 11) * (1.0 / 9007199254740992.0);  // [0, 1)
  return amplitude * (2.0 * u - 1.0);
}

std::vector<int> decode_track(const HeadModel& model, const FeatureTrack& track) {
  return decode_clusters(model.hmms, model.bigram, model.decode, model.normalise(track.features));
}

PoseTrack smooth_clusters(const HeadModel& model, const std::vector<int>& clusters, double t0_s,
                          double frame_rate_hz) {
  PoseTrack out;
  if (clusters.empty()) return out;
  const SmoothingOptions& so = model.smoothing;
  auto frame_quat = [&](double t) {
    const double idx = std::round((t - t0_s) * frame_rate_hz);
    const auto i =
        static_cast<std::size_t>(std::clamp(idx, 0.0, static_cast<double>(clusters.size() - 1)));
    const Eigen::Vector3d m = model.cluster_pose(clusters[i]);
    return euler_to_quat({m(0), m(1), m(2)});
  };
  const double end_t = t0_s + static_cast<double>(clusters.size() - 1) / frame_rate_hz;
  const auto n_keys = static_cast<std::size_t>(std::floor(end_t * so.key_rate_hz)) + 2;
  std::vector<Eigen::Quaterniond> keys;
  for (std::size_t k = 0; k < n_keys; ++k)
    keys.push_back(frame_quat(static_cast<double>(k) / so.key_rate_hz));
  const SquadCurve curve(std::move(keys));
  const auto n_out = static_cast<std::size_t>(std::floor(end_t * so.output_rate_hz)) + 1;
  for (std::size_t j = 0; j < n_out; ++j) {
    const double t = static_cast<double>(j) / so.output_rate_hz;
    Euler e = quat_to_euler(curve(t * so.key_rate_hz));
    e.yaw += pose_noise(so.seed, j, 0, so.noise_deg);
    e.pitch += pose_noise(so.seed, j, 1, so.noise_deg);
    e.roll += pose_noise(so.seed, j, 2, so.noise_deg);
    out.times.push_back(t);
    out.poses.push_back(e);
  }
  return out;
}

PoseTrack synthesize(const HeadModel& model, const FeatureTrack& track) {
  return smooth_clusters(model, decode_track(model, track), track.t0_s, track.frame_rate_hz);
}

PoseTrack synthesize(const HeadModel& model, const Audio& audio) {
  return synthesize(model, extract_features(audio, model.features));
}

}  // namespace animrt::head
