#include "animrt/controllers/seqnet/inference.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <stdexcept>

#include "animrt/core/error.hpp"

namespace animrt::seqnet {
namespace {

// The model file's parameters by name, each taken once with the shape the
// network needs (the libtorch network's names: docs/seqnet.md).
class Parameters {
 public:
  Parameters(const ModelFile& model, std::string file) : model_(model), file_(std::move(file)) {}

  Eigen::MatrixXf matrix(const std::string& name, int rows, int cols) {
    const NamedArray& a = find(name, {rows, cols});
    // Stored row-major (out x in).
    return Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        a.values.data(), rows, cols);
  }
  Eigen::VectorXf vector(const std::string& name, int size) {
    const NamedArray& a = find(name, {size});
    return Eigen::Map<const Eigen::VectorXf>(a.values.data(), size);
  }
  // Every array of the file has been taken.
  void check_all_used() const {
    for (const NamedArray& a : model_.parameters) {
      if (used_.count(a.name) == 0) {
        throw InputError(Location{file_, 0, 0}, "parameter " + a.name,
                         "not a parameter of this network");
      }
    }
  }

 private:
  const NamedArray& find(const std::string& name, const std::vector<std::int64_t>& want) {
    for (const NamedArray& a : model_.parameters) {
      if (a.name != name) continue;
      if (a.shape != want) {
        throw InputError(Location{file_, 0, 0}, "parameter " + name,
                         "shape " + text(a.shape) + ", the network needs " + text(want));
      }
      used_.insert(name);
      return a;
    }
    throw InputError(Location{file_, 0, 0}, "parameter " + name, "missing from the file");
  }
  static std::string text(const std::vector<std::int64_t>& s) {
    std::string out;
    for (auto d : s) out += (out.empty() ? "" : "x") + std::to_string(d);
    return out.empty() ? std::string("scalar") : out;
  }

  const ModelFile& model_;
  std::string file_;
  std::set<std::string> used_;
};

float sigmoid(float x) { return 1.0F / (1.0F + std::exp(-x)); }

// A standard normal draw (Box-Muller), the same on every platform for a
// generator state.
double standard_normal(std::mt19937_64& rng) {
  const double u1 = (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
  const double u2 = (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace

SeqNetInference::SeqNetInference(const ModelFile& model, const std::string& file)
    : shape_(model.shape), low_(model.low), high_(model.high) {
  const bool mesh = shape_.kind == ModelKind::mesh;
  const int d = shape_.input_dims();
  if (static_cast<int>(low_.size()) != d || static_cast<int>(high_.size()) != d) {
    throw InputError(
        Location{file, 0, 0}, "mapping",
        std::to_string(low_.size()) + " dimensions, the shape has " + std::to_string(d));
  }
  if (shape_.conv_layers < 1 || shape_.lstm_layers < 1 || d < 1) {
    throw InputError(Location{file, 0, 0}, "shape",
                     "no input dimension, no encoder layer or no LSTM layer");
  }
  vertices_ = mesh ? shape_.nodes() : 1;  // placement nodes have no neighbours
  if (mesh) {
    std::vector<std::set<int>> ring(static_cast<std::size_t>(vertices_));
    for (const auto& t : model.triangles) {
      for (int k = 0; k < 3; ++k) {
        const int a = t[static_cast<std::size_t>(k)];
        const int b = t[static_cast<std::size_t>((k + 1) % 3)];
        ring[static_cast<std::size_t>(a)].insert(b);
        ring[static_cast<std::size_t>(b)].insert(a);
      }
    }
    ring_start_.push_back(0);
    for (const auto& r : ring) {
      ring_index_.insert(ring_index_.end(), r.begin(), r.end());
      ring_start_.push_back(static_cast<int>(ring_index_.size()));
      degree_inverse_.push_back(r.empty() ? 0.0F : 1.0F / static_cast<float>(r.size()));
    }
  }

  Parameters p(model, file);
  const int width = mesh ? shape_.channels : shape_.dense_width;
  const int io = mesh ? 9 : shape_.joint_count;  // channels of a frame
  auto layer = [&](const std::string& prefix, int in, int out, bool transpose) {
    Layer l;
    if (mesh) {
      l.self = p.matrix(prefix + ".self.weight", out, in);
      l.bias = p.vector(prefix + ".self.bias", out);
      l.neighbours = p.matrix(prefix + ".neighbours.weight", out, in);
    } else {
      l.self = p.matrix(prefix + ".weight", out, in);
      l.bias = p.vector(prefix + ".bias", out);
    }
    l.transpose = transpose;
    l.out.resize(out, vertices_);
    l.ring.resize(out, vertices_);
    return l;
  };
  // Sequential modules number their children, the tanh layers included.
  for (int k = 0; k < shape_.conv_layers; ++k) {
    encoder_.push_back(
        layer("encoder." + std::to_string(2 * k), k == 0 ? io : width, width, false));
  }
  const int flat = width * vertices_;
  to_mu_ = p.matrix("to_mu.weight", shape_.latent, flat);
  to_mu_bias_ = p.vector("to_mu.bias", shape_.latent);
  p.matrix("to_logvar.weight", shape_.latent, flat);  // training only
  p.vector("to_logvar.bias", shape_.latent);
  const int h = shape_.hidden;
  for (int l = 0; l < shape_.lstm_layers; ++l) {
    const std::string n = std::to_string(l);
    w_ih_.push_back(p.matrix("lstm.weight_ih_l" + n, 4 * h, l == 0 ? shape_.latent : h));
    w_hh_.push_back(p.matrix("lstm.weight_hh_l" + n, 4 * h, h));
    lstm_bias_.push_back(p.vector("lstm.bias_ih_l" + n, 4 * h) +
                         p.vector("lstm.bias_hh_l" + n, 4 * h));
  }
  from_hidden_ = p.matrix("from_hidden.weight", flat, h);
  from_hidden_bias_ = p.vector("from_hidden.bias", flat);
  for (int k = 0; k < shape_.conv_layers; ++k) {
    const bool last = k + 1 == shape_.conv_layers;
    decoder_.push_back(layer("decoder." + std::to_string(2 * k), width, last ? io : width, true));
  }
  p.check_all_used();
  mu_.resize(shape_.latent);
  gates_.resize(4 * h);
  hidden_flat_.resize(flat);
}

Eigen::MatrixXf SeqNetInference::normalise(const FrameMatrix& frames) const {
  if (frames.rows() != dims()) {
    throw std::invalid_argument("frames of " + std::to_string(frames.rows()) +
                                " numbers, the model takes " + std::to_string(dims()));
  }
  Eigen::MatrixXf out(frames.rows(), frames.cols());
  for (Eigen::Index c = 0; c < frames.cols(); ++c) {
    for (Eigen::Index i = 0; i < frames.rows(); ++i) {
      const double low = low_[static_cast<std::size_t>(i)];
      const double range = high_[static_cast<std::size_t>(i)] - low;
      const double v = frames(i, c);
      out(i, c) = static_cast<float>(range > 0.0 ? (v - low) / range * 1.9 - 0.95 : v - low);
    }
  }
  return out;
}

FrameMatrix SeqNetInference::denormalise(const Eigen::MatrixXf& normalised) const {
  FrameMatrix out(normalised.rows(), normalised.cols());
  for (Eigen::Index c = 0; c < normalised.cols(); ++c) {
    for (Eigen::Index i = 0; i < normalised.rows(); ++i) {
      const double low = low_[static_cast<std::size_t>(i)];
      const double range = high_[static_cast<std::size_t>(i)] - low;
      const double x = normalised(i, c);
      out(i, c) = range > 0.0 ? (x + 0.95) / 1.9 * range + low : x + low;
    }
  }
  return out;
}

LstmCellState SeqNetInference::initial_state(double sign) const {
  const auto v = static_cast<float>(sign * shape_.s0);
  return {Eigen::MatrixXf::Constant(shape_.hidden, shape_.lstm_layers, v),
          Eigen::MatrixXf::Constant(shape_.hidden, shape_.lstm_layers, v)};
}

LstmCellState SeqNetInference::random_state(double sign, std::mt19937_64& rng) const {
  const double mean = sign * shape_.s0, sd = std::abs(shape_.s0);
  LstmCellState s{Eigen::MatrixXf(shape_.hidden, shape_.lstm_layers),
                  Eigen::MatrixXf(shape_.hidden, shape_.lstm_layers)};
  for (Eigen::Index i = 0; i < s.h.size(); ++i) {
    s.h(i) = static_cast<float>(mean + sd * standard_normal(rng));
  }
  for (Eigen::Index i = 0; i < s.c.size(); ++i) {
    s.c(i) = static_cast<float>(mean + sd * standard_normal(rng));
  }
  return s;
}

void SeqNetInference::apply(Layer& l, const Eigen::Ref<const Eigen::MatrixXf>& in) {
  l.out.noalias() = l.self * in;
  l.out.colwise() += l.bias;
  if (l.neighbours.size() == 0) return;
  // W2 applied per vertex first, then the ring mean (or its adjoint): the
  // same sum, far fewer operations than averaging the inputs first.
  l.ring.noalias() = l.neighbours * in;
  for (int i = 0; i < vertices_; ++i) {
    auto out = l.out.col(i);
    for (int k = ring_start_[static_cast<std::size_t>(i)];
         k < ring_start_[static_cast<std::size_t>(i) + 1]; ++k) {
      const int j = ring_index_[static_cast<std::size_t>(k)];
      const float w = degree_inverse_[static_cast<std::size_t>(l.transpose ? j : i)];
      out += w * l.ring.col(j);
    }
  }
}

const Eigen::VectorXf& SeqNetInference::encode(const Eigen::VectorXf& x) {
  if (x.size() != dims()) throw std::invalid_argument("encode: frame of the wrong size");
  const Eigen::Map<const Eigen::MatrixXf> frame(x.data(), dims() / vertices_, vertices_);
  for (std::size_t k = 0; k < encoder_.size(); ++k) {
    if (k == 0) {
      apply(encoder_[k], frame);
    } else {
      apply(encoder_[k], encoder_[k - 1].out);
    }
    encoder_[k].out = encoder_[k].out.array().tanh();
  }
  const Eigen::MatrixXf& h = encoder_.back().out;
  mu_.noalias() = to_mu_ * Eigen::Map<const Eigen::VectorXf>(h.data(), h.size());
  mu_ += to_mu_bias_;
  return mu_;
}

void SeqNetInference::step(Eigen::VectorXf& x, LstmCellState& state) {
  encode(x);
  const int h = shape_.hidden;
  for (int l = 0; l < shape_.lstm_layers; ++l) {
    // PyTorch's layout: gates i, f, g, o; layer l's input is layer l - 1's
    // new output.
    const std::size_t k = static_cast<std::size_t>(l);
    if (l == 0) {
      gates_.noalias() = w_ih_[k] * mu_;
    } else {
      gates_.noalias() = w_ih_[k] * state.h.col(l - 1);
    }
    gates_.noalias() += w_hh_[k] * state.h.col(l);
    gates_ += lstm_bias_[k];
    for (int j = 0; j < h; ++j) {
      const float in = sigmoid(gates_(j));
      const float forget = sigmoid(gates_(h + j));
      const float cell = std::tanh(gates_(2 * h + j));
      const float out = sigmoid(gates_(3 * h + j));
      state.c(j, l) = forget * state.c(j, l) + in * cell;
      state.h(j, l) = out * std::tanh(state.c(j, l));
    }
  }
  hidden_flat_.noalias() = from_hidden_ * state.h.col(shape_.lstm_layers - 1);
  hidden_flat_ += from_hidden_bias_;
  hidden_flat_ = hidden_flat_.array().tanh();
  const Eigen::Map<const Eigen::MatrixXf> hidden(hidden_flat_.data(),
                                                 hidden_flat_.size() / vertices_, vertices_);
  for (std::size_t k = 0; k < decoder_.size(); ++k) {
    if (k == 0) {
      apply(decoder_[k], hidden);
    } else {
      apply(decoder_[k], decoder_[k - 1].out);
    }
    if (k + 1 < decoder_.size()) decoder_[k].out = decoder_[k].out.array().tanh();
  }
  const Eigen::MatrixXf& dx = decoder_.back().out;
  x += Eigen::Map<const Eigen::VectorXf>(dx.data(), dx.size());
}

Eigen::MatrixXf SeqNetInference::run(const Eigen::MatrixXf& given, int n, LstmCellState state) {
  if (given.rows() != dims() || given.cols() < 1 || n < 1) {
    throw std::invalid_argument("run: no given frame, or frames of the wrong size");
  }
  Eigen::MatrixXf frames(dims(), n);
  frames.col(0) = given.col(0);
  Eigen::VectorXf x = given.col(0);
  for (int t = 1; t < n; ++t) {
    step(x, state);
    if (t < given.cols()) x = given.col(t);
    frames.col(t) = x;
  }
  return frames;
}

Eigen::MatrixXf SeqNetInference::chain(const Eigen::MatrixXf& context, int frames, double sign,
                                       std::mt19937_64* rng) {
  const auto u = static_cast<int>(context.cols());
  const int total = u + frames;
  Eigen::MatrixXf all(dims(), total);
  all.leftCols(u) = context;
  int have = u;
  while (have < total) {
    const int n = std::min(shape_.window, u + total - have);
    const LstmCellState state = rng != nullptr ? random_state(sign, *rng) : initial_state(sign);
    const Eigen::MatrixXf run_frames = run(all.middleCols(have - u, u), n, state);
    all.middleCols(have, n - u) = run_frames.rightCols(n - u);
    have += n - u;
  }
  return all;
}

FrameMatrix SeqNetInference::generate(const FrameMatrix& initial, int frames,
                                      std::optional<std::uint64_t> random_state, double sign) {
  const auto u = static_cast<int>(initial.cols());
  if (u < 1 || u >= shape_.window) {
    throw std::invalid_argument(std::to_string(u) + " initial frames: give 1 to " +
                                std::to_string(shape_.window - 1) + " (the model's window is " +
                                std::to_string(shape_.window) + " frames)");
  }
  if (frames < 0) throw std::invalid_argument("a negative number of frames to generate");
  std::mt19937_64 rng(random_state.value_or(0));
  FrameMatrix out =
      denormalise(chain(normalise(initial), frames, sign, random_state ? &rng : nullptr));
  out.leftCols(u) = initial;
  return out;
}

double SeqNetInference::frame_difference(const Eigen::VectorXf& a, const Eigen::VectorXf& b) {
  if (a.size() == 0) return 0.0;
  const double mean_square = (a - b).cast<double>().squaredNorm() / static_cast<double>(a.size());
  return std::sqrt(mean_square) / 1.9;
}

Completion SeqNetInference::complete(const FrameMatrix& keys, const std::vector<int>& gaps,
                                     const CompletionOptions& options) {
  if (keys.cols() < 2) {
    throw std::invalid_argument("completion needs at least 2 keys, got " +
                                std::to_string(keys.cols()));
  }
  if (gaps.size() + 1 != static_cast<std::size_t>(keys.cols())) {
    throw std::invalid_argument(std::to_string(keys.cols()) + " keys need " +
                                std::to_string(keys.cols() - 1) + " gaps, got " +
                                std::to_string(gaps.size()));
  }
  for (int g : gaps) {
    if (g < 1)
      throw std::invalid_argument("a gap of " + std::to_string(g) + " frames (at least 1)");
  }
  if (!(options.threshold > 0.0) || !std::isfinite(options.threshold)) {
    throw std::invalid_argument("threshold " + std::to_string(options.threshold) +
                                ": must be a positive number");
  }
  if (options.retries < 0) throw std::invalid_argument("a negative number of retries");
  const Eigen::MatrixXf normal_keys = normalise(keys);

  Completion result;
  int total = 1;
  for (int g : gaps) total += g + 1;
  Eigen::MatrixXf out(dims(), total);
  int at = 0;
  for (std::size_t g = 0; g < gaps.size(); ++g) {
    const int n = gaps[g];
    const auto col = static_cast<Eigen::Index>(g);
    std::mt19937_64 rng(options.seed * 0x9E3779B97F4A7C15ULL + g + 1);
    GapReport best;
    Eigen::MatrixXf best_forward, best_backward;
    for (int attempt = 0; attempt <= options.retries; ++attempt) {
      std::mt19937_64* draw = attempt == 0 ? nullptr : &rng;
      // Column t of the forward chain is frame t of the gap (0: the first
      // key); column j of the backward chain is frame n + 1 - j.
      Eigen::MatrixXf forward = chain(normal_keys.col(col), n, 1.0, draw);
      Eigen::MatrixXf backward = chain(normal_keys.col(col + 1), n, -1.0, draw);
      int frame = 1;
      double difference = frame_difference(forward.col(1), backward.col(n));
      for (int t = 2; t <= n; ++t) {
        const double d = frame_difference(forward.col(t), backward.col(n + 1 - t));
        if (d < difference) {
          difference = d;
          frame = t;
        }
      }
      if (attempt == 0 || difference < best.difference) {
        best.frame = frame;
        best.difference = difference;
        best_forward = std::move(forward);
        best_backward = std::move(backward);
      }
      best.tries = attempt + 1;
      if (difference < options.threshold) break;
    }
    best.gap = n;
    best.merged = best.difference < options.threshold;
    // Blended: each chain weighted by its nearness to its own key. Handed
    // over: forward frames before the merge frame, the mean of the pair at
    // it, backward frames after it.
    out.col(at) = normal_keys.col(col);
    for (int t = 1; t <= n; ++t) {
      if (options.blend) {
        const float s = static_cast<float>(t) / static_cast<float>(n + 1);
        out.col(at + t) = (1.0F - s) * best_forward.col(t) + s * best_backward.col(n + 1 - t);
      } else if (t < best.frame) {
        out.col(at + t) = best_forward.col(t);
      } else if (t == best.frame) {
        out.col(at + t) = 0.5F * (best_forward.col(t) + best_backward.col(n + 1 - t));
      } else {
        out.col(at + t) = best_backward.col(n + 1 - t);
      }
    }
    result.gaps.push_back(best);
    at += n + 1;
  }
  result.frames = denormalise(out);
  // The keys exactly as given.
  at = 0;
  for (std::size_t g = 0; g <= gaps.size(); ++g) {
    result.frames.col(at) = keys.col(static_cast<Eigen::Index>(g));
    if (g < gaps.size()) at += gaps[g] + 1;
  }
  return result;
}

}  // namespace animrt::seqnet
