// Forward-backward and Viterbi for Gaussian-mixture HMMs (Baum-Welch
// training: controllers/learn/head/hmm_training.cpp).

#include "animrt/controllers/head/hmm.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace animrt::head {

double log_add(double a, double b) {
  if (a == kLogZero) return b;
  if (b == kLogZero) return a;
  if (a < b) std::swap(a, b);
  return a + std::log1p(std::exp(b - a));
}

const char* topology_name(Topology t) { return t == Topology::kLeftToRight ? "LR" : "EG"; }

double log_sum(const Eigen::Ref<const Eigen::VectorXd>& v) {
  const double m = v.maxCoeff();
  if (m == kLogZero) return kLogZero;
  return m + std::log((v.array() - m).exp().sum());
}

void GaussianMixture::component_log_densities(const Eigen::Ref<const Eigen::VectorXd>& x,
                                              Eigen::VectorXd& out) const {
  const Eigen::Index m = means.rows();
  const double log2pi = std::log(2.0 * std::numbers::pi);
  out.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto var = variances.row(i).array();
    const double maha = ((x.transpose().array() - means.row(i).array()).square() / var).sum();
    out(i) =
        log_weights(i) - 0.5 * (maha + var.log().sum() + static_cast<double>(x.size()) * log2pi);
  }
}

double GaussianMixture::log_density(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  Eigen::VectorXd c;
  component_log_densities(x, c);
  return log_sum(c);
}

Eigen::MatrixXd Hmm::emission_log_probs(const Eigen::MatrixXd& obs) const {
  Eigen::MatrixXd out(obs.rows(), num_states());
  for (Eigen::Index t = 0; t < obs.rows(); ++t) {
    for (int s = 0; s < num_states(); ++s) {
      out(t, s) = states[static_cast<std::size_t>(s)].log_density(obs.row(t).transpose());
    }
  }
  return out;
}

double forward(const Hmm& hmm, const Eigen::MatrixXd& log_b, Eigen::MatrixXd& la) {
  const Eigen::Index T = log_b.rows(), S = hmm.num_states();
  la.setConstant(T, S, kLogZero);
  if (T == 0) return kLogZero;
  for (Eigen::Index s = 0; s < S; ++s) la(0, s) = hmm.log_pi(s) + log_b(0, s);
  for (Eigen::Index t = 1; t < T; ++t) {
    for (Eigen::Index j = 0; j < S; ++j) {
      double acc = kLogZero;
      for (Eigen::Index i = 0; i < S; ++i) acc = log_add(acc, la(t - 1, i) + hmm.log_a(i, j));
      la(t, j) = acc + log_b(t, j);
    }
  }
  double p = kLogZero;
  for (Eigen::Index s = 0; s < S; ++s) p = log_add(p, la(T - 1, s) + hmm.log_exit(s));
  return p;
}

double backward(const Hmm& hmm, const Eigen::MatrixXd& log_b, Eigen::MatrixXd& lb) {
  const Eigen::Index T = log_b.rows(), S = hmm.num_states();
  lb.setConstant(T, S, kLogZero);
  if (T == 0) return kLogZero;
  for (Eigen::Index s = 0; s < S; ++s) lb(T - 1, s) = hmm.log_exit(s);
  for (Eigen::Index t = T - 2; t >= 0; --t) {
    for (Eigen::Index i = 0; i < S; ++i) {
      double acc = kLogZero;
      for (Eigen::Index j = 0; j < S; ++j) {
        acc = log_add(acc, hmm.log_a(i, j) + log_b(t + 1, j) + lb(t + 1, j));
      }
      lb(t, i) = acc;
    }
  }
  double p = kLogZero;
  for (Eigen::Index s = 0; s < S; ++s) p = log_add(p, hmm.log_pi(s) + log_b(0, s) + lb(0, s));
  return p;
}

double viterbi(const Hmm& hmm, const Eigen::MatrixXd& log_b, std::vector<int>& path) {
  const Eigen::Index T = log_b.rows(), S = hmm.num_states();
  path.clear();
  if (T == 0) return kLogZero;
  Eigen::MatrixXd delta(T, S);
  Eigen::MatrixXi back = Eigen::MatrixXi::Constant(T, S, -1);
  for (Eigen::Index s = 0; s < S; ++s) delta(0, s) = hmm.log_pi(s) + log_b(0, s);
  for (Eigen::Index t = 1; t < T; ++t) {
    for (Eigen::Index j = 0; j < S; ++j) {
      double best = kLogZero;
      int arg = -1;
      for (Eigen::Index i = 0; i < S; ++i) {
        const double v = delta(t - 1, i) + hmm.log_a(i, j);
        if (v > best) {
          best = v;
          arg = static_cast<int>(i);
        }
      }
      delta(t, j) = best + log_b(t, j);
      back(t, j) = arg;
    }
  }
  double best = kLogZero;
  int arg = -1;
  for (Eigen::Index s = 0; s < S; ++s) {
    const double v = delta(T - 1, s) + hmm.log_exit(s);
    if (v > best) {
      best = v;
      arg = static_cast<int>(s);
    }
  }
  if (arg < 0) return kLogZero;
  path.assign(static_cast<std::size_t>(T), 0);
  for (Eigen::Index t = T - 1; t >= 0; --t) {
    path[static_cast<std::size_t>(t)] = arg;
    if (t > 0) arg = back(t, arg);
  }
  return best;
}

}  // namespace animrt::head
