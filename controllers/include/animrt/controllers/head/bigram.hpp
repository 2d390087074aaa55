#pragma once
// Bigram prior over head-pose clusters: P(first cluster) and P(next | previous)
// learned from the cluster sequences of the training data (one count per
// change of cluster), smoothed so that a pair never seen keeps a small
// probability instead of zero.
//
// Smoothing: interpolated absolute discounting (discount D) onto an add-one
// unigram, per row i with c(i) = sum_j c(i, j) and n(i) distinct successors:
//   P(j | i) = max(c(i, j) - D, 0) / c(i) + D n(i) / c(i) * P_uni(j)
// and P(j | i) = P_uni(j) for a row never seen. Every row sums to one.

#include <Eigen/Core>
#include <vector>

namespace animrt::head {

struct Bigram {
  Eigen::VectorXd log_initial;  // K
  Eigen::MatrixXd log_next;     // K x K, row = previous cluster
  int size() const { return static_cast<int>(log_initial.size()); }
};

// `sequences`: per utterance, the cluster of every frame (runs of the same
// cluster count once: the prior is over changes of pose, not over frames).
Bigram train_bigram(const std::vector<std::vector<int>>& sequences, int k, double discount = 0.5);

// Collapses runs: {3,3,1,1,1,3} -> {3,1,3}.
std::vector<int> collapse_runs(const std::vector<int>& labels);

}  // namespace animrt::head
