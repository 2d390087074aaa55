#pragma once
// Estimating the bigram prior over head-pose clusters
// (controllers/head/bigram.hpp: the prior and its smoothing).

#include <vector>

#include "animrt/controllers/head/bigram.hpp"

namespace animrt::head {

// `sequences`: per utterance, the cluster of every frame (runs of the same
// cluster count once: the prior is over changes of pose, not over frames).
Bigram train_bigram(const std::vector<std::vector<int>>& sequences, int k, double discount = 0.5);

// Collapses runs: {3,3,1,1,1,3} -> {3,1,3}.
std::vector<int> collapse_runs(const std::vector<int>& labels);

}  // namespace animrt::head
