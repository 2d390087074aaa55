#pragma once
// Offline synthesis: features -> most likely cluster sequence -> each
// cluster's pose (its mean moved toward the mean pose: cluster_pose()) ->
// quaternions -> key poses every 1/key_rate s -> SQUAD to the output rate ->
// Euler angles + seeded uniform noise.

#include <vector>

#include "animrt/controllers/head/model.hpp"
#include "animrt/controllers/head/pose_io.hpp"

namespace animrt::head {

// Cluster of every frame of `track`.
std::vector<int> decode_track(const HeadModel& model, const FeatureTrack& track);

// Smooths a per-frame cluster sequence (frame i at t0 + i / frame_rate) into
// poses at the output rate, from t = 0 to the last frame's time.
PoseTrack smooth_clusters(const HeadModel& model, const std::vector<int>& clusters, double t0_s,
                          double frame_rate_hz);

PoseTrack synthesize(const HeadModel& model, const FeatureTrack& track);
PoseTrack synthesize(const HeadModel& model, const Audio& audio);

// Deterministic uniform noise in [-amplitude, amplitude] for output sample
// `index` and angle `axis` (0..2): the same for offline and streaming.
double pose_noise(std::uint64_t seed, std::uint64_t index, int axis, double amplitude);

}  // namespace animrt::head
