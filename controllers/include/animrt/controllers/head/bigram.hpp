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

}  // namespace animrt::head
