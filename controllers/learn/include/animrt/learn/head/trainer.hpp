#pragma once
// Training a head model from prepared utterances: LBG codebook of the poses,
// the frames' clusters (the known segmentation), one HMM per cluster on the
// normalised prosodic features of its segments (initialised from the
// segmentation, refined by Baum-Welch), and the bigram over cluster changes.

#include <functional>
#include <string>
#include <vector>

#include "animrt/controllers/head/model.hpp"
#include "animrt/learn/head/corpus.hpp"
#include "animrt/learn/head/lbg.hpp"

namespace animrt::head {

struct TrainOptions {
  int clusters = 16;  // K
  int states = 3;     // S
  int mixtures = 2;   // M
  Topology topology = Topology::kLeftToRight;
  int iterations = 10;           // Baum-Welch iterations per HMM at most
  double variance_floor = 0.01;  // per dimension, of the normalised features' unit variance
  double bigram_discount = 0.5;
  LbgOptions lbg;
  DecodeOptions decode;
  SmoothingOptions smoothing;
  // Shrink of the output poses toward the mean pose (SmoothingOptions::shrink):
  // a value in [0, 1] for all axes, or negative to choose one per axis on the
  // training data by 4-fold cross-validation (see docs/head.md). 1 is the paper.
  double shrink = -1.0;
  std::function<void(const std::string&)> log;  // progress, may be empty
};

// `features` in the prepared utterances must come from the FeatureConfig that
// the model will record (pass it as `config`).
HeadModel train_model(const std::vector<PreparedUtterance>& train, const FeatureConfig& config,
                      const TrainOptions& options);

}  // namespace animrt::head
