#pragma once
// Continuous-density HMMs in log space: diagonal-covariance Gaussian mixture
// per state, HTK-style entry and exit (a sequence starts in a state drawn
// from pi and ends by leaving through exit; for every state
// sum_j a(i, j) + exit(i) = 1 once trained). Left-to-right models enter at
// the first state, move only to themselves or the next state and leave from
// the last; ergodic models allow every transition, entry and exit.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

namespace animrt::head {

constexpr double kLogZero = -std::numeric_limits<double>::infinity();

// log(exp(a) + exp(b)) without overflow; handles -inf.
double log_add(double a, double b);
// log(sum exp(v)) without overflow; kLogZero when every entry is.
double log_sum(const Eigen::Ref<const Eigen::VectorXd>& v);

enum class Topology { kLeftToRight, kErgodic };
const char* topology_name(Topology t);  // "LR" or "EG"

struct GaussianMixture {
  Eigen::VectorXd log_weights;  // M
  Eigen::MatrixXd means;        // M x D
  Eigen::MatrixXd variances;    // M x D (diagonal covariances)
  int components() const { return static_cast<int>(means.rows()); }
  double log_density(const Eigen::Ref<const Eigen::VectorXd>& x) const;
  // Per-component log(w_m N_m(x)) into `out` (size M).
  void component_log_densities(const Eigen::Ref<const Eigen::VectorXd>& x,
                               Eigen::VectorXd& out) const;
};

struct Hmm {
  Topology topology = Topology::kLeftToRight;
  Eigen::VectorXd log_pi;    // S, entry
  Eigen::MatrixXd log_a;     // S x S
  Eigen::VectorXd log_exit;  // S
  std::vector<GaussianMixture> states;
  int num_states() const { return static_cast<int>(states.size()); }
  int dim() const { return states.empty() ? 0 : static_cast<int>(states[0].means.cols()); }

  // T x S matrix of log b_s(o_t) for the rows of `obs` (T x D).
  Eigen::MatrixXd emission_log_probs(const Eigen::MatrixXd& obs) const;
};

// Forward: log alpha (T x S); returns log P(O) = log sum_s alpha_T(s) exit(s).
double forward(const Hmm& hmm, const Eigen::MatrixXd& log_b, Eigen::MatrixXd& log_alpha);
// Backward: log beta (T x S) with beta_T(s) = exit(s); returns log P(O).
double backward(const Hmm& hmm, const Eigen::MatrixXd& log_b, Eigen::MatrixXd& log_beta);
// Most likely state path; returns its log probability (exit included), or
// kLogZero (empty path) when no path exists.
double viterbi(const Hmm& hmm, const Eigen::MatrixXd& log_b, std::vector<int>& path);

}  // namespace animrt::head
