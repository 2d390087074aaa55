// Token-passing Viterbi over cluster HMMs with a bigram between them.

#include "animrt/controllers/head/decoder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace animrt::head {

NetworkDecoder::NetworkDecoder(const std::vector<Hmm>& hmms, const Bigram& bigram,
                               DecodeOptions options, int lag_frames)
    : hmms_(hmms), bigram_(bigram), options_(options), lag_(lag_frames) {
  k_ = static_cast<int>(hmms.size());
  if (k_ == 0 || bigram.size() != k_) throw std::invalid_argument("decoder: model count mismatch");
  for (const Hmm& h : hmms) {
    offset_.push_back(n_);
    for (int s = 0; s < h.num_states(); ++s) owner_.push_back(static_cast<int>(offset_.size()) - 1);
    n_ += h.num_states();
    s_max_ = std::max(s_max_, h.num_states());
  }
  delta_.resize(n_);
  next_.resize(n_);
  log_b_.resize(n_);
  exit_score_.resize(k_);
  entry_score_.resize(k_);
  entry_from_.resize(static_cast<std::size_t>(k_));
  exit_from_.resize(static_cast<std::size_t>(k_));
  dim_ = hmms.front().dim();
  for (const Hmm& h : hmms) {
    for (const GaussianMixture& g : h.states) {
      comp_begin_.push_back(static_cast<int>(comp_log_weight_.size()));
      for (Eigen::Index c = 0; c < g.means.rows(); ++c) {
        for (int d = 0; d < dim_; ++d) {
          comp_mean_.push_back(g.means(c, d));
          comp_var_.push_back(g.variances(c, d));
        }
        comp_log_weight_.push_back(g.log_weights(c));
        // The same expression as GaussianMixture::component_log_densities,
        // so the sum (and every score) is the same to the last bit.
        comp_log_var_sum_.push_back(g.variances.row(c).array().log().sum());
      }
    }
  }
  comp_begin_.push_back(static_cast<int>(comp_log_weight_.size()));
  if (lag_ >= 0)
    back_.assign((static_cast<std::size_t>(lag_) + 1) * static_cast<std::size_t>(n_), 0);
  reset();
}

void NetworkDecoder::reset() {
  frames_ = 0;
  committed_ = 0;
  if (lag_ < 0) back_.clear();
}

int NetworkDecoder::trace(long from_frame, int state, long to_frame) const {
  const auto n = static_cast<std::size_t>(n_);
  const std::size_t ring = back_.size() / n;
  for (long t = from_frame; t > to_frame; --t) {
    const std::size_t slot =
        lag_ >= 0 ? static_cast<std::size_t>(t) % ring : static_cast<std::size_t>(t);
    state = back_[slot * n + static_cast<std::size_t>(state)];
  }
  return state;
}

// log b_i(obs) of every network state: GaussianMixture::component_log_densities
// and the log-sum-exp over the components, in the same order of operations,
// on the flattened components with their log variance sums computed once.
void NetworkDecoder::emission_log_probs(const Eigen::Ref<const Eigen::VectorXd>& obs) {
  const double dim_term = static_cast<double>(obs.size()) * std::log(2.0 * std::numbers::pi);
  for (int i = 0; i < n_; ++i) {
    const int first = comp_begin_[static_cast<std::size_t>(i)];
    const int end = comp_begin_[static_cast<std::size_t>(i) + 1];
    comp_.resize(end - first);
    for (int c = first; c < end; ++c) {
      const double* mean =
          &comp_mean_[static_cast<std::size_t>(c) * static_cast<std::size_t>(dim_)];
      const double* var = &comp_var_[static_cast<std::size_t>(c) * static_cast<std::size_t>(dim_)];
      double maha = 0.0;
      for (int d = 0; d < dim_; ++d) {
        const double diff = obs(d) - mean[d];
        maha += diff * diff / var[d];
      }
      comp_(c - first) = comp_log_weight_[static_cast<std::size_t>(c)] -
                         0.5 * (maha + comp_log_var_sum_[static_cast<std::size_t>(c)] + dim_term);
    }
    const double m = comp_.maxCoeff();
    log_b_(i) = m == kLogZero ? kLogZero : m + std::log((comp_.array() - m).exp().sum());
  }
}

bool NetworkDecoder::push(const Eigen::Ref<const Eigen::VectorXd>& obs, int& cluster) {
  emission_log_probs(obs);
  const auto n = static_cast<std::size_t>(n_);
  if (lag_ < 0) back_.resize(back_.size() + n);
  const std::size_t slot =
      lag_ >= 0 ? static_cast<std::size_t>(frames_) % (back_.size() / n) : back_.size() / n - 1;
  int* back = &back_[slot * n];
  if (frames_ == 0) {
    for (int k = 0; k < k_; ++k) {
      const Hmm& h = hmms_[static_cast<std::size_t>(k)];
      for (int s = 0; s < h.num_states(); ++s) {
        const int i = offset_[static_cast<std::size_t>(k)] + s;
        delta_(i) = options_.lm_scale * bigram_.log_initial(k) + h.log_pi(s) + log_b_(i);
        back[i] = -1;
      }
    }
  } else {
    // Best exit of every model, then the best way into every model.
    std::vector<int>& exit_from = exit_from_;
    std::fill(exit_from.begin(), exit_from.end(), -1);
    for (int k = 0; k < k_; ++k) {
      const Hmm& h = hmms_[static_cast<std::size_t>(k)];
      double best = kLogZero;
      for (int s = 0; s < h.num_states(); ++s) {
        const double v = delta_(offset_[static_cast<std::size_t>(k)] + s) + h.log_exit(s);
        if (v > best) {
          best = v;
          exit_from[static_cast<std::size_t>(k)] = offset_[static_cast<std::size_t>(k)] + s;
        }
      }
      exit_score_(k) = best;
    }
    for (int k = 0; k < k_; ++k) {
      double best = kLogZero;
      int arg = -1;
      for (int p = 0; p < k_; ++p) {
        if (exit_score_(p) == kLogZero) continue;
        const double v = exit_score_(p) + options_.lm_scale * bigram_.log_next(p, k);
        if (v > best) {
          best = v;
          arg = exit_from[static_cast<std::size_t>(p)];
        }
      }
      entry_score_(k) = best + options_.switch_penalty;
      entry_from_[static_cast<std::size_t>(k)] = arg;
    }
    for (int k = 0; k < k_; ++k) {
      const Hmm& h = hmms_[static_cast<std::size_t>(k)];
      const int o = offset_[static_cast<std::size_t>(k)];
      for (int j = 0; j < h.num_states(); ++j) {
        double best = entry_score_(k) + h.log_pi(j);
        int arg = entry_from_[static_cast<std::size_t>(k)];
        for (int i = 0; i < h.num_states(); ++i) {
          const double v = delta_(o + i) + h.log_a(i, j);
          if (v > best) {
            best = v;
            arg = o + i;
          }
        }
        next_(o + j) = best + log_b_(o + j);
        back[o + j] = arg;
      }
    }
    delta_.swap(next_);
  }
  // Keep scores near zero so long streams never lose precision.
  const double top = delta_.maxCoeff();
  if (top != kLogZero) delta_.array() -= top;
  ++frames_;
  if (lag_ < 0 || frames_ - 1 < lag_) return false;
  Eigen::Index best = 0;
  delta_.maxCoeff(&best);
  const long target = frames_ - 1 - lag_;
  cluster = owner_[static_cast<std::size_t>(trace(frames_ - 1, static_cast<int>(best), target))];
  committed_ = target + 1;
  return true;
}

void NetworkDecoder::finish(std::vector<int>& clusters) {
  if (frames_ == 0) return;
  int best = -1;
  double best_v = kLogZero;
  for (int i = 0; i < n_; ++i) {
    const Hmm& h = hmms_[static_cast<std::size_t>(owner_[static_cast<std::size_t>(i)])];
    const double v =
        delta_(i) +
        h.log_exit(i - offset_[static_cast<std::size_t>(owner_[static_cast<std::size_t>(i)])]);
    if (v > best_v) {
      best_v = v;
      best = i;
    }
  }
  if (best < 0) {  // no model can end here: take the best state anyway
    Eigen::Index arg = 0;
    delta_.maxCoeff(&arg);
    best = static_cast<int>(arg);
  }
  const std::size_t start = clusters.size();
  clusters.resize(start + static_cast<std::size_t>(frames_ - committed_));
  int state = best;
  for (long t = frames_ - 1; t >= committed_; --t) {
    clusters[start + static_cast<std::size_t>(t - committed_)] =
        owner_[static_cast<std::size_t>(state)];
    if (t > committed_) state = trace(t, state, t - 1);
  }
  committed_ = frames_;
}

std::vector<int> decode_clusters(const std::vector<Hmm>& hmms, const Bigram& bigram,
                                 const DecodeOptions& options, const Eigen::MatrixXd& obs) {
  NetworkDecoder decoder(hmms, bigram, options, -1);
  int unused = 0;
  for (Eigen::Index t = 0; t < obs.rows(); ++t) decoder.push(obs.row(t).transpose(), unused);
  std::vector<int> out;
  decoder.finish(out);
  return out;
}

}  // namespace animrt::head
