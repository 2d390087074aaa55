#pragma once
// Training a vector-quantisation codebook (controllers/head/vq.hpp holds the
// codebook that plays) by Linde-Buzo-Gray splitting and Lloyd iterations.

#include <Eigen/Core>

#include "animrt/controllers/head/vq.hpp"

namespace animrt::head {

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
