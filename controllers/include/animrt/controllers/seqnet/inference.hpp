#pragma once
// The trained sequence network's forward pass in plain C++ (Eigen, no
// libtorch), read from a model file: encode a frame to its latent mean, step
// the LSTM, decode the feature change, X(t+1) = X(t) + dX. On it: generation
// from initial frames (paper section 4.3) and completion between keyframes
// (section 4.4). Both model kinds run the same code: a joint model is a
// "mesh" of one vertex whose layers have no neighbour term.
//
// Frames are columns of numbers in the model's own units: joint angles in
// the model's joint order, or a mesh's raw deformation features (9 per
// vertex, vertex-major). The network itself works on the normalised values
// (each dimension's training range mapped to [-0.95, 0.95]).
//
// One object holds scratch buffers for the steps: use one per thread.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/model_file.hpp"

namespace animrt::seqnet {

// Frames in the model's units, one column per frame.
using FrameMatrix = Eigen::MatrixXd;

// LSTM state: h and c, one column per layer (hidden x layers).
struct LstmCellState {
  Eigen::MatrixXf h;
  Eigen::MatrixXf c;
};

struct CompletionOptions {
  // Largest accepted difference between the forward and backward frame
  // where they are merged, as defined at frame_difference().
  double threshold = 0.05;
  // Tries with random initial states after the first (which uses s0).
  int retries = 20;
  std::uint64_t seed = 1;
  // true: each in-between frame is the two chains weighted by its distance
  // from their keys, (1 - s) forward + s backward with s = t / (gap + 1), so
  // chains that change nothing give linear interpolation of the keys. false:
  // the paper's hand-over (forward frames up to where the chains are
  // closest, backward frames after it).
  bool blend = true;
};

// How one gap between two keys was filled.
struct GapReport {
  int gap = 0;             // frames between the two keys
  bool merged = false;     // difference below the threshold
  int frame = 0;           // 1..gap: where the forward chain hands over to the backward one
  double difference = 0;   // frame_difference() there
  int tries = 0;           // runs made (1 + random retries)
};

struct Completion {
  // Key k at column offset(k) = sum_{i<k} (gaps[i] + 1), the gap's frames
  // between; key columns are the given keys, bit for bit.
  FrameMatrix frames;
  std::vector<GapReport> gaps;
};

class SeqNetInference {
 public:
  // Throws InputError naming `file` and the parameter when one is missing,
  // of another shape, or when the file has parameters the network lacks.
  SeqNetInference(const ModelFile& model, const std::string& file);

  const NetShape& shape() const { return shape_; }
  int dims() const { return shape_.input_dims(); }

  // Model units <-> normalised network input, per dimension
  // x = (v - low) / (high - low) * 1.9 - 0.95 (v - low for a dimension that
  // never changed in training), as FeatureScale does.
  Eigen::MatrixXf normalise(const FrameMatrix& frames) const;
  FrameMatrix denormalise(const Eigen::MatrixXf& normalised) const;

  // Every entry sign * s0 (sign +1: forward chain, -1: backward chain).
  LstmCellState initial_state(double sign) const;
  // Every entry drawn from N(sign * s0, s0^2).
  LstmCellState random_state(double sign, std::mt19937_64& rng) const;

  // The latent mean of one normalised frame (valid until the next call).
  const Eigen::VectorXf& encode(const Eigen::VectorXf& x);
  // One step of a chain: x <- x + dX(x, state), the state advanced.
  void step(Eigen::VectorXf& x, LstmCellState& state);
  // A chain of n frames (normalised, dims x n) from the given ones (dims x u,
  // u >= 1): the given frames are fed in order, then each output is the next
  // input; column 0 is given column 0. The same as the libtorch network's
  // SeqNetImpl::run with latent means.
  Eigen::MatrixXf run(const Eigen::MatrixXf& given, int n, LstmCellState state);

  // The initial frames (model units, dims x u, 1 <= u < window) followed by
  // `frames` generated ones. Long sequences chain windows of the model's
  // length, each run started from the last u frames with a fresh state:
  // sign * s0, or with `random_state` every entry of every run drawn from
  // N(sign * s0, s0^2) with that seed. The initial columns are returned
  // unchanged. Throws std::invalid_argument for bad arguments.
  FrameMatrix generate(const FrameMatrix& initial, int frames,
                       std::optional<std::uint64_t> random_state = std::nullopt, double sign = 1.0);

  // Completion between keys (dims x K, K >= 2, model units), gaps[k] >= 1
  // frames between key k and key k + 1 (docs/seqnet.md, "Completion").
  // Throws std::invalid_argument for bad arguments.
  Completion complete(const FrameMatrix& keys, const std::vector<int>& gaps,
                      const CompletionOptions& options = {});

  // The difference between two normalised frames: the root mean square over
  // the dimensions of a - b, as a fraction of each dimension's training range
  // (the normalised span 1.9). 0.05 is 5 % of the range.
  static double frame_difference(const Eigen::VectorXf& a, const Eigen::VectorXf& b);

 private:
  struct Layer {
    Eigen::MatrixXf self;        // out x in
    Eigen::MatrixXf neighbours;  // out x in; empty for a dense layer
    Eigen::VectorXf bias;
    bool transpose = false;      // spread to the neighbours (decoder) instead of gathering
    Eigen::MatrixXf out;         // scratch: out x vertices
    Eigen::MatrixXf ring;        // scratch: out x vertices
  };
  void apply(Layer& layer, const Eigen::Ref<const Eigen::MatrixXf>& in);
  Eigen::MatrixXf chain(const Eigen::MatrixXf& context, int frames, double sign,
                        std::mt19937_64* rng);

  NetShape shape_;
  int vertices_ = 1;  // 1 for a joint model
  std::vector<double> low_, high_;
  // The 1-ring (mesh models): neighbours of vertex i at ring_index_[ring_start_[i] ..
  // ring_start_[i + 1]); the mean weighs them 1 / d_i, the transpose 1 / d_j.
  std::vector<int> ring_start_, ring_index_;
  std::vector<float> degree_inverse_;
  std::vector<Layer> encoder_, decoder_;
  Eigen::MatrixXf to_mu_, from_hidden_;
  Eigen::VectorXf to_mu_bias_, from_hidden_bias_;
  std::vector<Eigen::MatrixXf> w_ih_, w_hh_;
  std::vector<Eigen::VectorXf> lstm_bias_;  // b_ih + b_hh
  // Scratch.
  Eigen::VectorXf mu_, gates_, layer_in_, hidden_flat_;
};

}  // namespace animrt::seqnet
