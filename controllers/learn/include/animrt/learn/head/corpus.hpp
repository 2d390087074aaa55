#pragma once
// A corpus on disk: a folder of utterances, each an audio file NAME.wav and
// a head-pose file with the same stem: NAME.csv (Euler angles), NAME.bvh or
// NAME.markers.csv (see pose_io.hpp). Files are taken in name order.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "animrt/controllers/head/pose_io.hpp"
#include "animrt/controllers/head/prosody.hpp"

namespace animrt::head {

struct Utterance {
  std::string name;  // the stem
  std::string audio_path;
  std::string pose_path;
};

// Lists the utterances; InputError for a missing folder, an empty corpus or
// an audio file without a pose file.
std::vector<Utterance> list_corpus(const std::string& dir);

// An utterance ready for learning: its features and, at every feature frame,
// the head pose (the pose track interpolated to the frame times).
struct PreparedUtterance {
  std::string name;
  FeatureTrack track;
  Eigen::MatrixXd poses;  // frames x 3: yaw, pitch, roll in degrees
};

PreparedUtterance prepare_utterance(const Utterance& u, const FeatureConfig& config);
std::vector<PreparedUtterance> prepare_corpus(const std::vector<Utterance>& utterances,
                                              const FeatureConfig& config);

// Seeded shuffle, then the first round(fraction * n) (at least one, and at
// least one left for testing when n >= 2) are for training.
struct CorpusSplit {
  std::vector<Utterance> train, test;
};
CorpusSplit split_corpus(const std::vector<Utterance>& utterances, double train_fraction = 0.8,
                         std::uint64_t seed = 1);

}  // namespace animrt::head
