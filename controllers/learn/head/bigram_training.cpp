#include "animrt/learn/head/bigram_training.hpp"

#include <cmath>
#include <stdexcept>

namespace animrt::head {

std::vector<int> collapse_runs(const std::vector<int>& labels) {
  std::vector<int> out;
  for (int l : labels) {
    if (out.empty() || out.back() != l) out.push_back(l);
  }
  return out;
}

Bigram train_bigram(const std::vector<std::vector<int>>& sequences, int k, double discount) {
  if (k < 1) throw std::invalid_argument("bigram: K must be >= 1");
  if (!(discount > 0 && discount < 1))
    throw std::invalid_argument("bigram: discount must be in (0, 1)");
  Eigen::MatrixXd pair = Eigen::MatrixXd::Zero(k, k);
  Eigen::VectorXd unigram = Eigen::VectorXd::Ones(k);  // add-one
  Eigen::VectorXd first = Eigen::VectorXd::Ones(k);
  for (const auto& seq : sequences) {
    const std::vector<int> runs = collapse_runs(seq);
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (runs[i] < 0 || runs[i] >= k) throw std::invalid_argument("bigram: label out of range");
      unigram(runs[i]) += 1;
      if (i == 0) first(runs[i]) += 1;
      if (i > 0) pair(runs[i - 1], runs[i]) += 1;
    }
  }
  const Eigen::VectorXd p_uni = unigram / unigram.sum();
  Bigram b;
  b.log_initial = (first / first.sum()).array().log();
  b.log_next.resize(k, k);
  for (int i = 0; i < k; ++i) {
    const double c = pair.row(i).sum();
    if (c <= 0) {
      b.log_next.row(i) = p_uni.transpose().array().log();
      continue;
    }
    const double seen = static_cast<double>((pair.row(i).array() > 0).count());
    for (int j = 0; j < k; ++j) {
      const double p = std::max(pair(i, j) - discount, 0.0) / c + discount * seen / c * p_uni(j);
      b.log_next(i, j) = std::log(p);
    }
  }
  return b;
}

}  // namespace animrt::head
