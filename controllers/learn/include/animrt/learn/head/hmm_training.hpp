#pragma once
// Training Gaussian-mixture HMMs (controllers/head/hmm.hpp holds the models
// and the decoding that plays): initialisation from known segments and
// Baum-Welch re-estimation.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "animrt/controllers/head/hmm.hpp"

namespace animrt::head {

struct HmmTrainOptions {
  int states = 3;
  int mixtures = 2;
  Topology topology = Topology::kLeftToRight;
  int max_iterations = 20;
  double tolerance = 1e-4;         // stop when the mean per-frame log likelihood gains less
  Eigen::VectorXd variance_floor;  // D, absolute
  std::uint64_t seed = 1;
};

// Initialises an HMM from sequences known to belong to it: each sequence is
// cut into `states` equal parts (the known segmentation), each state's
// mixture starts from k-means of its frames, transitions from the counts.
// Sequences shorter than the number of states are ignored by left-to-right
// models. Needs at least one usable frame.
Hmm init_hmm(const std::vector<Eigen::MatrixXd>& sequences, const HmmTrainOptions& options);

// Baum-Welch re-estimation over all sequences. Returns the total log
// likelihood of the usable sequences before each iteration and after the last
// (non-decreasing up to rounding).
std::vector<double> baum_welch(Hmm& hmm, const std::vector<Eigen::MatrixXd>& sequences,
                               const HmmTrainOptions& options);

}  // namespace animrt::head
