#pragma once
// Linde-Buzo-Gray vector quantisation: K code vectors (Voronoi regions), each
// with the mean and covariance of the vectors it holds.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace animrt::head {

struct Codebook {
  Eigen::MatrixXd means;                     // K x D
  std::vector<Eigen::MatrixXd> covariances;  // K of D x D
  int size() const { return static_cast<int>(means.rows()); }
  int dim() const { return static_cast<int>(means.cols()); }
  // Index of the nearest code vector (Euclidean).
  int nearest(const Eigen::Ref<const Eigen::VectorXd>& x) const;
};

struct LbgOptions {
  double split_epsilon = 0.05;  // split offset, in units of the data's per-dimension std
  double tolerance = 1e-5;      // stop Lloyd iterations when distortion improves less (relative)
  int max_iterations = 100;     // Lloyd iterations per codebook size
};

// Trains a K-vector codebook on the rows of `data` (N x D, N >= K). Starts
// from the global mean, splits every code vector in two (c +- epsilon*std)
// until K are reached (splitting the most distorted cells first when K is not
// a power of two), refining with Lloyd iterations after every split; an empty
// cell is re-seeded by splitting the most distorted one.
Codebook train_lbg(const Eigen::MatrixXd& data, int k, const LbgOptions& options = {});

// Mean squared distance of the rows of `data` to their nearest code vector.
double distortion(const Codebook& codebook, const Eigen::MatrixXd& data);

}  // namespace animrt::head
