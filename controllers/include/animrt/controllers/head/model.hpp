#pragma once
// A trained head-motion model: feature settings and normalisation, the pose
// codebook, one HMM per cluster, the bigram, decoding and smoothing settings,
// and which utterances it was trained on. Saved as versioned text
// (first line "animrt-head-model 3"); see docs/head.md.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "animrt/controllers/head/bigram.hpp"
#include "animrt/controllers/head/decoder.hpp"
#include "animrt/controllers/head/hmm.hpp"
#include "animrt/controllers/head/prosody.hpp"
#include "animrt/controllers/head/vq.hpp"

namespace animrt::head {

constexpr int kModelFormatVersion = 3;  // 2: F0 in semitones, energy in dB; 3: shrink line

struct SmoothingOptions {
  double key_rate_hz = 6.0;       // key poses per second (the paper's 6)
  double output_rate_hz = 120.0;  // poses per second out of SQUAD
  double noise_deg = 0.5;         // half-width of the uniform noise on each angle
  std::uint64_t seed = 1;
  // Output pose of cluster k = pose_mean + shrink * (cluster mean - pose_mean),
  // per axis (yaw, pitch, roll). 1 outputs the cluster means as the paper
  // does; below 1 a wrongly decoded cluster costs less (see docs/head.md).
  Eigen::Vector3d shrink = Eigen::Vector3d::Ones();
};

struct HeadModel {
  FeatureConfig features;
  Eigen::VectorXd feature_mean, feature_std;  // 6: observations are (x - mean) / std
  Codebook codebook;                          // Euler angles (yaw, pitch, roll) in degrees
  Eigen::Vector3d pose_mean = Eigen::Vector3d::Zero();  // mean training pose, degrees
  std::vector<Hmm> hmms;                                // one per cluster
  Bigram bigram;
  DecodeOptions decode;
  SmoothingOptions smoothing;
  int states = 0, mixtures = 0;
  Topology topology = Topology::kLeftToRight;
  std::vector<std::string> training_utterances;

  int clusters() const { return codebook.size(); }
  // The pose (yaw, pitch, roll in degrees) that synthesis shows for cluster k.
  Eigen::Vector3d cluster_pose(int k) const {
    return pose_mean + smoothing.shrink.cwiseProduct(codebook.means.row(k).transpose() - pose_mean);
  }
  // Normalised observations for the HMMs.
  Eigen::MatrixXd normalise(const Eigen::MatrixXd& raw) const;
};

void save_model(const std::string& path, const HeadModel& model);
// Throws InputError naming the file, the line and the key for a missing,
// corrupt, truncated, inconsistent or other-version file.
HeadModel load_model(const std::string& path);

}  // namespace animrt::head
