// Initialisation and Baum-Welch re-estimation of Gaussian-mixture HMMs.

#include "animrt/learn/head/hmm_training.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace animrt::head {

namespace {

double safe_log(double p) { return p > 0 ? std::log(p) : kLogZero; }

}  // namespace

namespace {

// k-means (Lloyd, deterministic farthest-point seeding) into a mixture.
GaussianMixture fit_mixture(const Eigen::MatrixXd& x, int m, const Eigen::VectorXd& floor) {
  const Eigen::Index n = x.rows(), d = x.cols();
  GaussianMixture g;
  m = static_cast<int>(std::max<Eigen::Index>(1, std::min<Eigen::Index>(m, n)));
  Eigen::MatrixXd centres(m, d);
  centres.row(0) = x.colwise().mean();
  for (int c = 1; c < m; ++c) {
    Eigen::Index far = 0;
    Eigen::VectorXd dist(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      dist(i) = (centres.topRows(c).rowwise() - x.row(i)).rowwise().squaredNorm().minCoeff();
    }
    dist.maxCoeff(&far);
    centres.row(c) = x.row(far);
  }
  std::vector<int> label(static_cast<std::size_t>(n), 0);
  for (int iter = 0; iter < 20; ++iter) {
    bool changed = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      Eigen::Index best = 0;
      (centres.rowwise() - x.row(i)).rowwise().squaredNorm().minCoeff(&best);
      if (label[static_cast<std::size_t>(i)] != best) changed = true;
      label[static_cast<std::size_t>(i)] = static_cast<int>(best);
    }
    Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(m, d);
    Eigen::VectorXd counts = Eigen::VectorXd::Zero(m);
    for (Eigen::Index i = 0; i < n; ++i) {
      sums.row(label[static_cast<std::size_t>(i)]) += x.row(i);
      counts(label[static_cast<std::size_t>(i)]) += 1;
    }
    for (int c = 0; c < m; ++c) {
      if (counts(c) > 0) centres.row(c) = sums.row(c) / counts(c);
    }
    if (!changed && iter > 0) break;
  }
  g.means = centres;
  g.variances = Eigen::MatrixXd::Zero(m, d);
  Eigen::VectorXd counts = Eigen::VectorXd::Zero(m);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int c = label[static_cast<std::size_t>(i)];
    g.variances.row(c) += (x.row(i) - centres.row(c)).array().square().matrix();
    counts(c) += 1;
  }
  g.log_weights.resize(m);
  for (int c = 0; c < m; ++c) {
    if (counts(c) > 1) g.variances.row(c) /= counts(c);
    g.variances.row(c) = g.variances.row(c).cwiseMax(floor.transpose());
    g.log_weights(c) =
        std::log(std::max(counts(c), 0.5) / std::max<double>(static_cast<double>(n), 1.0));
  }
  g.log_weights.array() -= log_sum(g.log_weights);
  return g;
}

bool usable(const Hmm& hmm, const Eigen::MatrixXd& seq) {
  return seq.rows() > 0 && (hmm.topology == Topology::kErgodic || seq.rows() >= hmm.num_states());
}

}  // namespace

Hmm init_hmm(const std::vector<Eigen::MatrixXd>& sequences, const HmmTrainOptions& options) {
  const int S = options.states;
  if (S < 1 || options.mixtures < 1)
    throw std::invalid_argument("HMM: need >= 1 state and mixture");
  Hmm hmm;
  hmm.topology = options.topology;
  Eigen::Index d = 0;
  for (const auto& s : sequences) d = std::max(d, s.cols());
  std::vector<std::vector<Eigen::VectorXd>> frames(static_cast<std::size_t>(S));
  Eigen::MatrixXd counts = Eigen::MatrixXd::Zero(S, S);
  Eigen::VectorXd starts = Eigen::VectorXd::Zero(S), ends = Eigen::VectorXd::Zero(S);
  for (const auto& seq : sequences) {
    const Eigen::Index T = seq.rows();
    if (T == 0 || (options.topology == Topology::kLeftToRight && T < S)) continue;
    int prev = -1;
    for (Eigen::Index t = 0; t < T; ++t) {
      const int s = static_cast<int>((t * S) / T);
      frames[static_cast<std::size_t>(s)].push_back(seq.row(t).transpose());
      if (prev >= 0) counts(prev, s) += 1;
      if (t == 0) starts(s) += 1;
      prev = s;
    }
    ends(prev) += 1;
  }
  std::vector<Eigen::VectorXd> all;
  for (const auto& f : frames) all.insert(all.end(), f.begin(), f.end());
  if (all.empty()) {
    // No sequence long enough: use every frame of every sequence for all states.
    for (const auto& seq : sequences) {
      for (Eigen::Index t = 0; t < seq.rows(); ++t) all.push_back(seq.row(t).transpose());
    }
    if (all.empty()) throw std::invalid_argument("HMM: no training frames");
    for (auto& f : frames) f = all;
    for (int s = 0; s < S; ++s) counts(s, std::min(s + 1, S - 1)) += 1, counts(s, s) += 1;
    starts(0) += 1;
    ends(S - 1) += 1;
  }
  const Eigen::VectorXd floor = options.variance_floor.size() == d
                                    ? options.variance_floor
                                    : Eigen::VectorXd::Constant(d, 1e-6);
  for (int s = 0; s < S; ++s) {
    auto& f =
        frames[static_cast<std::size_t>(s)].empty() ? all : frames[static_cast<std::size_t>(s)];
    Eigen::MatrixXd x(static_cast<Eigen::Index>(f.size()), d);
    for (std::size_t i = 0; i < f.size(); ++i)
      x.row(static_cast<Eigen::Index>(i)) = f[i].transpose();
    hmm.states.push_back(fit_mixture(x, options.mixtures, floor));
  }
  // Transitions from the uniform segmentation's counts, self-loops included
  // (each state's frames minus its exits).
  for (int s = 0; s < S; ++s) {
    counts(s, s) += static_cast<double>(frames[static_cast<std::size_t>(s)].size()) -
                    counts.row(s).sum() - ends(s);
    counts(s, s) = std::max(counts(s, s), 0.0);
  }
  hmm.log_pi = Eigen::VectorXd::Constant(S, kLogZero);
  hmm.log_a = Eigen::MatrixXd::Constant(S, S, kLogZero);
  hmm.log_exit = Eigen::VectorXd::Constant(S, kLogZero);
  if (options.topology == Topology::kLeftToRight) {
    hmm.log_pi(0) = 0.0;
    for (int s = 0; s < S; ++s) {
      const double stay = counts(s, s) + 1.0;
      const double go = (s + 1 < S ? counts(s, s + 1) : ends(s)) + 1.0;
      hmm.log_a(s, s) = std::log(stay / (stay + go));
      if (s + 1 < S) {
        hmm.log_a(s, s + 1) = std::log(go / (stay + go));
      } else {
        hmm.log_exit(s) = std::log(go / (stay + go));
      }
    }
  } else {
    // Ergodic: the counts plus a small floor on every transition, entry and exit.
    const Eigen::VectorXd pi = (starts.array() + 0.1) / (starts.sum() + 0.1 * S);
    for (int s = 0; s < S; ++s) {
      hmm.log_pi(s) = std::log(pi(s));
      const double total = counts.row(s).sum() + ends(s) + 0.1 * (S + 1);
      for (int j = 0; j < S; ++j) hmm.log_a(s, j) = std::log((counts(s, j) + 0.1) / total);
      hmm.log_exit(s) = std::log((ends(s) + 0.1) / total);
    }
  }
  return hmm;
}

std::vector<double> baum_welch(Hmm& hmm, const std::vector<Eigen::MatrixXd>& sequences,
                               const HmmTrainOptions& options) {
  const int S = hmm.num_states();
  const Eigen::Index D = hmm.dim();
  const Eigen::VectorXd floor = options.variance_floor.size() == D
                                    ? options.variance_floor
                                    : Eigen::VectorXd::Constant(D, 1e-6);
  std::vector<double> history;
  double frames_total = 0;
  for (const auto& seq : sequences) {
    if (usable(hmm, seq)) frames_total += static_cast<double>(seq.rows());
  }
  for (int iter = 0; iter <= options.max_iterations; ++iter) {
    // Accumulators.
    Eigen::VectorXd pi_acc = Eigen::VectorXd::Zero(S), exit_acc = Eigen::VectorXd::Zero(S),
                    occ = Eigen::VectorXd::Zero(S);
    Eigen::MatrixXd a_acc = Eigen::MatrixXd::Zero(S, S);
    std::vector<Eigen::VectorXd> w_acc(static_cast<std::size_t>(S));
    std::vector<Eigen::MatrixXd> mean_acc(static_cast<std::size_t>(S)),
        sq_acc(static_cast<std::size_t>(S));
    for (int s = 0; s < S; ++s) {
      const int M = hmm.states[static_cast<std::size_t>(s)].components();
      w_acc[static_cast<std::size_t>(s)] = Eigen::VectorXd::Zero(M);
      mean_acc[static_cast<std::size_t>(s)] = Eigen::MatrixXd::Zero(M, D);
      sq_acc[static_cast<std::size_t>(s)] = Eigen::MatrixXd::Zero(M, D);
    }
    double total = 0;
    int used = 0;
    Eigen::MatrixXd la, lb;
    Eigen::VectorXd comp;
    for (const auto& seq : sequences) {
      if (!usable(hmm, seq)) continue;
      const Eigen::MatrixXd log_b = hmm.emission_log_probs(seq);
      const double lp = forward(hmm, log_b, la);
      if (!std::isfinite(lp)) continue;
      backward(hmm, log_b, lb);
      total += lp;
      ++used;
      const Eigen::Index T = seq.rows();
      for (Eigen::Index t = 0; t < T; ++t) {
        for (int s = 0; s < S; ++s) {
          const double g = std::exp(la(t, s) + lb(t, s) - lp);
          if (g <= 0) continue;
          occ(s) += g;
          if (t == 0) pi_acc(s) += g;
          if (t == T - 1) exit_acc(s) += g;
          const GaussianMixture& gm = hmm.states[static_cast<std::size_t>(s)];
          gm.component_log_densities(seq.row(t).transpose(), comp);
          const double norm = log_sum(comp);
          for (int m = 0; m < gm.components(); ++m) {
            const double gm_post = g * std::exp(comp(m) - norm);
            w_acc[static_cast<std::size_t>(s)](m) += gm_post;
            mean_acc[static_cast<std::size_t>(s)].row(m) += gm_post * seq.row(t);
            sq_acc[static_cast<std::size_t>(s)].row(m) +=
                gm_post * seq.row(t).array().square().matrix();
          }
        }
        if (t + 1 < T) {
          for (int i = 0; i < S; ++i) {
            if (la(t, i) == kLogZero) continue;
            for (int j = 0; j < S; ++j) {
              if (hmm.log_a(i, j) == kLogZero) continue;
              a_acc(i, j) +=
                  std::exp(la(t, i) + hmm.log_a(i, j) + log_b(t + 1, j) + lb(t + 1, j) - lp);
            }
          }
        }
      }
    }
    history.push_back(total);
    if (used == 0 || iter == options.max_iterations) break;
    if (iter > 0 &&
        (total - history[history.size() - 2]) / std::max(frames_total, 1.0) < options.tolerance) {
      break;
    }
    // Re-estimate. Structural zeros stay zero because their accumulators do.
    const double pi_sum = pi_acc.sum();
    for (int s = 0; s < S; ++s) {
      if (pi_sum > 0 && hmm.topology == Topology::kErgodic)
        hmm.log_pi(s) = safe_log(pi_acc(s) / pi_sum);
      if (occ(s) <= 1e-10) continue;  // unseen state: keep its parameters
      for (int j = 0; j < S; ++j) {
        if (hmm.log_a(s, j) != kLogZero) hmm.log_a(s, j) = safe_log(a_acc(s, j) / occ(s));
      }
      if (hmm.log_exit(s) != kLogZero) hmm.log_exit(s) = safe_log(exit_acc(s) / occ(s));
      GaussianMixture& gm = hmm.states[static_cast<std::size_t>(s)];
      const Eigen::VectorXd& w = w_acc[static_cast<std::size_t>(s)];
      for (int m = 0; m < gm.components(); ++m) {
        if (w(m) <= 1e-10) {
          gm.log_weights(m) = kLogZero;
          continue;
        }
        gm.log_weights(m) = std::log(w(m) / occ(s));
        const Eigen::RowVectorXd mean = mean_acc[static_cast<std::size_t>(s)].row(m) / w(m);
        const Eigen::RowVectorXd var =
            (sq_acc[static_cast<std::size_t>(s)].row(m) / w(m)).array() - mean.array().square();
        gm.means.row(m) = mean;
        gm.variances.row(m) = var.cwiseMax(floor.transpose());
      }
      // A component that lost all weight cannot come back; keep the mixture
      // normalised over the living ones.
      gm.log_weights.array() -= log_sum(gm.log_weights);
    }
  }
  return history;
}

}  // namespace animrt::head
