// The codebook's nearest code vector (training: controllers/learn/head/lbg.cpp).

#include "animrt/controllers/head/vq.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace animrt::head {

int Codebook::nearest(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  int best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (int k = 0; k < size(); ++k) {
    const double d = (means.row(k).transpose() - x).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

}  // namespace animrt::head
