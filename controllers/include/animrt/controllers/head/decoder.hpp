#pragma once
// Viterbi over the network of cluster HMMs joined by the bigram: the most
// likely cluster sequence for a feature sequence. Leaving model k' (through
// its exit) and entering model k (through its entry) scores
//   lm_scale * log P(k | k') + switch_penalty.
// With a bounded lag the decoder commits frame t - lag when frame t arrives
// (fixed-lag traceback from the best state at t), so it can run on a stream.

#include <Eigen/Core>
#include <vector>

#include "animrt/controllers/head/bigram.hpp"
#include "animrt/controllers/head/hmm.hpp"

namespace animrt::head {

struct DecodeOptions {
  double lm_scale = 1.0;
  // Log units, <= 0 discourages switching (like a word insertion penalty);
  // -40 was best on the generated corpus (docs/head.md).
  double switch_penalty = -40.0;
};

class NetworkDecoder {
 public:
  // `lag_frames` < 0: unbounded (offline; commits only in finish()).
  NetworkDecoder(const std::vector<Hmm>& hmms, const Bigram& bigram, DecodeOptions options,
                 int lag_frames);

  // Pushes one observation. Returns true and sets `cluster` when a frame
  // (the one `lag` frames back) was committed.
  bool push(const Eigen::Ref<const Eigen::VectorXd>& obs, int& cluster);
  // End of input: appends the clusters of the frames not yet committed, along
  // the best complete path.
  void finish(std::vector<int>& clusters);
  void reset();
  int lag_frames() const { return lag_; }

 private:
  int trace(long from_frame, int from_state, long to_frame) const;
  void emission_log_probs(const Eigen::Ref<const Eigen::VectorXd>& obs);
  const std::vector<Hmm>& hmms_;
  const Bigram& bigram_;
  DecodeOptions options_;
  int lag_;
  int k_ = 0, s_max_ = 0, n_ = 0;  // clusters, largest state count, network size
  std::vector<int> offset_;        // first network index of cluster k
  std::vector<int> owner_;         // cluster of network index
  Eigen::VectorXd delta_, next_, log_b_, comp_, exit_score_, entry_score_;
  std::vector<int> entry_from_;  // best predecessor network index per entered cluster
  std::vector<int> exit_from_;   // best exit state per cluster
  // The mixtures' components flattened in network order (state i owns
  // components comp_begin_[i] .. comp_begin_[i + 1] - 1), each with its
  // log variance sum, which depends on the model alone.
  std::vector<int> comp_begin_;
  std::vector<double> comp_mean_, comp_var_, comp_log_weight_, comp_log_var_sum_;
  int dim_ = 0;
  // Backpointers, n_ per frame: a ring of lag + 1 frames, or every frame.
  std::vector<int> back_;
  long frames_ = 0;     // frames pushed
  long committed_ = 0;  // frames committed
};

// Offline: the cluster of every row of `obs`.
std::vector<int> decode_clusters(const std::vector<Hmm>& hmms, const Bigram& bigram,
                                 const DecodeOptions& options, const Eigen::MatrixXd& obs);

}  // namespace animrt::head
