// LBG: split and refine.

#include "animrt/learn/head/lbg.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace animrt::head {

double distortion(const Codebook& codebook, const Eigen::MatrixXd& data) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    const int k = codebook.nearest(data.row(i).transpose());
    sum += (data.row(i) - codebook.means.row(k)).squaredNorm();
  }
  return data.rows() > 0 ? sum / static_cast<double>(data.rows()) : 0.0;
}

namespace {

// Lloyd iterations; returns per-cell distortion sums and counts.
void lloyd(const Eigen::MatrixXd& data, Eigen::MatrixXd& means, const Eigen::VectorXd& spread,
           const LbgOptions& options, std::vector<double>& cell_distortion,
           std::vector<int>& count) {
  const Eigen::Index k = means.rows();
  double previous = std::numeric_limits<double>::infinity();
  std::vector<int> label(static_cast<std::size_t>(data.rows()));
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    cell_distortion.assign(static_cast<std::size_t>(k), 0.0);
    count.assign(static_cast<std::size_t>(k), 0);
    Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(k, data.cols());
    double total = 0.0;
    for (Eigen::Index i = 0; i < data.rows(); ++i) {
      Eigen::Index best = 0;
      (means.rowwise() - data.row(i)).rowwise().squaredNorm().minCoeff(&best);
      const double d = (means.row(best) - data.row(i)).squaredNorm();
      cell_distortion[static_cast<std::size_t>(best)] += d;
      ++count[static_cast<std::size_t>(best)];
      sums.row(best) += data.row(i);
      total += d;
    }
    for (Eigen::Index c = 0; c < k; ++c) {
      if (count[static_cast<std::size_t>(c)] > 0) {
        means.row(c) = sums.row(c) / count[static_cast<std::size_t>(c)];
      }
    }
    // Re-seed empty cells next to the most distorted one.
    bool reseeded = false;
    for (Eigen::Index c = 0; c < k; ++c) {
      if (count[static_cast<std::size_t>(c)] > 0) continue;
      const auto worst = static_cast<Eigen::Index>(
          std::max_element(cell_distortion.begin(), cell_distortion.end()) -
          cell_distortion.begin());
      if (cell_distortion[static_cast<std::size_t>(worst)] <= 0) break;  // nothing left to split
      means.row(c) = means.row(worst) + options.split_epsilon * spread.transpose();
      means.row(worst) -= options.split_epsilon * spread.transpose();
      cell_distortion[static_cast<std::size_t>(worst)] = 0;
      reseeded = true;
    }
    if (!reseeded && previous - total <= options.tolerance * std::max(total, 1e-300)) break;
    previous = total;
  }
}

}  // namespace

Codebook train_lbg(const Eigen::MatrixXd& data, int k, const LbgOptions& options) {
  if (k < 1) throw std::invalid_argument("LBG: K must be >= 1");
  if (data.rows() < k) throw std::invalid_argument("LBG: fewer vectors than code vectors");
  const Eigen::RowVectorXd mean = data.colwise().mean();
  const Eigen::VectorXd spread =
      ((data.rowwise() - mean).array().square().colwise().mean().sqrt().transpose()).cwiseMax(1e-9);
  Eigen::MatrixXd means = mean;
  std::vector<double> cell(1, 0.0);
  std::vector<int> count(1, static_cast<int>(data.rows()));
  while (means.rows() < k) {
    const Eigen::Index current = means.rows();
    const Eigen::Index add = std::min<Eigen::Index>(current, k - current);
    // Split the `add` most distorted cells.
    std::vector<Eigen::Index> order(static_cast<std::size_t>(current));
    std::iota(order.begin(), order.end(), 0);
    if (add < current) {
      std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
        return cell[static_cast<std::size_t>(a)] > cell[static_cast<std::size_t>(b)];
      });
    }
    Eigen::MatrixXd next(current + add, data.cols());
    next.topRows(current) = means;
    for (Eigen::Index i = 0; i < add; ++i) {
      const Eigen::Index c = order[static_cast<std::size_t>(i)];
      next.row(current + i) = means.row(c) + options.split_epsilon * spread.transpose();
      next.row(c) = means.row(c) - options.split_epsilon * spread.transpose();
    }
    means = next;
    lloyd(data, means, spread, options, cell, count);
  }
  if (k == 1) lloyd(data, means, spread, options, cell, count);

  Codebook book;
  book.means = means;
  const Eigen::Index d = data.cols();
  std::vector<Eigen::MatrixXd> sums(static_cast<std::size_t>(k), Eigen::MatrixXd::Zero(d, d));
  std::vector<int> n(static_cast<std::size_t>(k), 0);
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    const int c = book.nearest(data.row(i).transpose());
    const Eigen::VectorXd diff = data.row(i) - means.row(c);
    sums[static_cast<std::size_t>(c)] += diff * diff.transpose();
    ++n[static_cast<std::size_t>(c)];
  }
  const Eigen::MatrixXd floor = (spread.array().square() * 1e-4).matrix().asDiagonal();
  for (int c = 0; c < k; ++c) {
    const auto i = static_cast<std::size_t>(c);
    book.covariances.push_back(
        (n[i] > 1 ? Eigen::MatrixXd(sums[i] / (n[i] - 1)) : Eigen::MatrixXd::Zero(d, d)) + floor);
  }
  return book;
}

}  // namespace animrt::head
