#pragma once
// A vector-quantisation codebook: K code vectors (Voronoi regions), each
// with the mean and covariance of the vectors it holds. Trained by
// Linde-Buzo-Gray splitting (controllers/learn/head/lbg.cpp).

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

}  // namespace animrt::head
