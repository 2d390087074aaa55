// The model file: one keyword per line followed by its values, in a fixed
// order, so a damaged file is reported at the line where it stops making
// sense.

#include <Eigen/Cholesky>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "animrt/controllers/head/model.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"

namespace animrt::head {

Eigen::MatrixXd HeadModel::normalise(const Eigen::MatrixXd& raw) const {
  return (raw.rowwise() - feature_mean.transpose()).array().rowwise() /
         feature_std.transpose().array();
}

namespace {

constexpr const char* kMagic = "animrt-head-model";

class Writer {
 public:
  explicit Writer(const std::string& path) : out_(path), path_(path) {
    if (!out_) throw std::runtime_error("cannot write " + path);
    out_ << std::setprecision(17);
  }
  Writer& key(const char* k) {
    out_ << k;
    return *this;
  }
  Writer& num(double v) {
    if (v == kLogZero) {
      out_ << " -inf";
    } else {
      out_ << ' ' << v;
    }
    return *this;
  }
  Writer& nums(const Eigen::Ref<const Eigen::VectorXd>& v) {
    for (Eigen::Index i = 0; i < v.size(); ++i) num(v(i));
    return *this;
  }
  Writer& word(const std::string& w) {
    out_ << ' ' << w;
    return *this;
  }
  void end() { out_ << '\n'; }
  void close() {
    out_.close();
    if (!out_) throw std::runtime_error("cannot write " + path_);
  }

 private:
  std::ofstream out_;
  std::string path_;
};

std::string read_model_file(const std::string& path) {
  if (input_file_problem(path) == kFileMissing)
    throw InputError(Location{path, 0, 0}, "", "model file not found");
  return read_input_file(path);
}

// Logarithms of probabilities are at most 0 (a little above, for rounding
// in the written digits).
constexpr double kLogOne = 1e-9;
constexpr const char* kLogProbabilityMessage = "log-probabilities must be at most 0";
template <typename Values>
bool log_probabilities(const Values& values) {
  return (values.array() <= kLogOne).all();
}

class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path), in_(read_model_file(path)) {}
  // Reads the next non-comment line and checks its keyword.
  void line(const std::string& keyword) {
    std::string text;
    while (true) {
      if (!std::getline(in_, text)) {
        throw InputError(Location{path_, line_no_ + 1, 0}, keyword,
                         "unexpected end of file (truncated model?), expected " + quote(keyword));
      }
      ++line_no_;
      // strtod and the word splitter would stop at a NUL and quietly accept
      // what came before it.
      if (const auto nul = text.find('\0'); nul != std::string::npos) {
        throw InputError(Location{path_, line_no_, static_cast<int>(nul) + 1}, keyword,
                         "NUL byte in the line (a corrupted or binary file?)");
      }
      if (!text.empty() && text[0] != '#') break;
    }
    tokens_.clear();
    pos_ = 0;
    std::istringstream ws(text);
    std::string w;
    while (ws >> w) tokens_.push_back(w);
    key_ = keyword;
    if (tokens_.empty() || tokens_[0] != keyword) {
      fail("expected a line starting with " + quote(keyword) + ", found " +
           quote(tokens_.empty() ? std::string() : tokens_[0]));
    }
    pos_ = 1;
  }
  // After the last line: nothing but blank lines and comments.
  void end_of_file() {
    std::string text;
    while (std::getline(in_, text)) {
      ++line_no_;
      if (text.find_first_not_of(" \t\r") != std::string::npos && text[0] != '#') {
        throw InputError(Location{path_, line_no_, 0}, "end",
                         "unexpected line after \"end\": " + quote(elide(text)));
      }
    }
  }
  std::string word() {
    if (pos_ >= tokens_.size()) fail("line ends too early");
    return tokens_[pos_++];
  }
  // A named value: "name value".
  std::string named(const std::string& name) {
    const std::string w = word();
    if (w != name) fail("expected " + quote(name) + ", found " + quote(w));
    return word();
  }
  double num() {
    const std::string w = word();
    if (w == "-inf") return kLogZero;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(w.c_str(), &end);
    if (*end != '\0' || errno == ERANGE || !std::isfinite(v))
      fail("expected a number, found " + quote(w));
    return v;
  }
  double named_num(const std::string& name) {
    const std::string w = word();
    if (w != name) fail("expected " + quote(name) + ", found " + quote(w));
    return num();
  }
  int named_int(const std::string& name, int lo, int hi) {
    const double v = named_num(name);
    if (v != std::floor(v) || v < lo || v > hi) {
      fail(name + ": expected a whole number from " + std::to_string(lo) + " to " +
           std::to_string(hi));
    }
    return static_cast<int>(v);
  }
  Eigen::VectorXd nums(Eigen::Index n) {
    Eigen::VectorXd v(n);
    for (Eigen::Index i = 0; i < n; ++i) v(i) = num();
    return v;
  }
  void done() {
    if (pos_ != tokens_.size()) fail("unexpected extra value " + quote(tokens_[pos_]));
  }
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(Location{path_, line_no_, 0}, key_, message);
  }
  void check(bool ok, const std::string& message) const {
    if (!ok) fail(message);
  }

 private:
  std::string path_;
  std::istringstream in_;
  std::vector<std::string> tokens_;
  std::size_t pos_ = 0;
  int line_no_ = 0;
  std::string key_;
};

}  // namespace

void save_model(const std::string& path, const HeadModel& m) {
  Writer w(path);
  w.key(kMagic).word(std::to_string(kModelFormatVersion)).end();
  const FeatureConfig& f = m.features;
  w.key("features")
      .word("sample_rate")
      .num(f.sample_rate)
      .word("window_s")
      .num(f.window_s)
      .word("frame_rate_hz")
      .num(f.frame_rate_hz)
      .word("method")
      .word(f.method)
      .word("f0_min_hz")
      .num(f.f0_min_hz)
      .word("f0_max_hz")
      .num(f.f0_max_hz)
      .word("voicing_threshold")
      .num(f.voicing_threshold)
      .word("silence_db")
      .num(f.silence_db)
      .word("delta_window")
      .num(f.delta_window)
      .end();
  w.key("normalisation").word("mean").nums(m.feature_mean).word("std").nums(m.feature_std).end();
  w.key("smoothing")
      .word("key_rate_hz")
      .num(m.smoothing.key_rate_hz)
      .word("output_rate_hz")
      .num(m.smoothing.output_rate_hz)
      .word("noise_deg")
      .num(m.smoothing.noise_deg)
      .word("seed")
      .num(static_cast<double>(m.smoothing.seed))
      .end();
  w.key("shrink").word("factor").nums(m.smoothing.shrink).word("toward").nums(m.pose_mean).end();
  w.key("decode")
      .word("lm_scale")
      .num(m.decode.lm_scale)
      .word("switch_penalty")
      .num(m.decode.switch_penalty)
      .end();
  w.key("config")
      .word("K")
      .num(m.clusters())
      .word("S")
      .num(m.states)
      .word("M")
      .num(m.mixtures)
      .word("topology")
      .word(topology_name(m.topology))
      .end();
  w.key("utterances").num(static_cast<double>(m.training_utterances.size())).end();
  for (const auto& u : m.training_utterances) w.key("utterance").word(u).end();
  w.key("codebook").word("K").num(m.clusters()).word("dim").num(m.codebook.dim()).end();
  for (int k = 0; k < m.clusters(); ++k) {
    const Eigen::MatrixXd& c = m.codebook.covariances[static_cast<std::size_t>(k)];
    w.key("cluster")
        .num(k)
        .word("mean")
        .nums(m.codebook.means.row(k).transpose())
        .word("cov")
        .nums(Eigen::Map<const Eigen::VectorXd>(c.data(), c.size()))
        .end();
  }
  for (int k = 0; k < m.clusters(); ++k) {
    const Hmm& h = m.hmms[static_cast<std::size_t>(k)];
    const int S = h.num_states();
    w.key("hmm")
        .num(k)
        .word("topology")
        .word(topology_name(h.topology))
        .word("states")
        .num(S)
        .word("mixtures")
        .num(h.states[0].components())
        .word("dim")
        .num(h.dim())
        .end();
    w.key("pi").nums(h.log_pi).end();
    for (int s = 0; s < S; ++s) w.key("a").nums(h.log_a.row(s).transpose()).end();
    w.key("exit").nums(h.log_exit).end();
    for (int s = 0; s < S; ++s) {
      const GaussianMixture& g = h.states[static_cast<std::size_t>(s)];
      for (int c = 0; c < g.components(); ++c) {
        w.key("mix")
            .num(g.log_weights(c))
            .word("mean")
            .nums(g.means.row(c).transpose())
            .word("var")
            .nums(g.variances.row(c).transpose())
            .end();
      }
    }
  }
  w.key("bigram").word("initial").nums(m.bigram.log_initial).end();
  for (int k = 0; k < m.clusters(); ++k)
    w.key("next").nums(m.bigram.log_next.row(k).transpose()).end();
  w.key("end").end();
  w.close();
}

HeadModel load_model(const std::string& path) {
  Reader r(path);
  HeadModel m;
  {
    std::istringstream probe(read_input_file(path));
    std::string first;
    std::getline(probe, first);
    if (first.rfind(kMagic, 0) != 0) {
      throw InputError(Location{path, 1, 1}, "",
                       std::string("not an animrt head model (the first line must be \"") + kMagic +
                           " " + std::to_string(kModelFormatVersion) + "\")");
    }
  }
  r.line(kMagic);
  const double version = r.num();
  if (version != kModelFormatVersion) {
    r.fail("model format version " + format_number(version) +
           " is not supported (this build reads version " + std::to_string(kModelFormatVersion) +
           "; retrain with `animrt head train`)");
  }
  r.done();
  r.line("features");
  FeatureConfig& f = m.features;
  f.sample_rate = r.named_int("sample_rate", 8000, 192000);
  f.window_s = r.named_num("window_s");
  f.frame_rate_hz = r.named_num("frame_rate_hz");
  f.method = r.named("method");
  f.f0_min_hz = r.named_num("f0_min_hz");
  f.f0_max_hz = r.named_num("f0_max_hz");
  f.voicing_threshold = r.named_num("voicing_threshold");
  f.silence_db = r.named_num("silence_db");
  f.delta_window = r.named_int("delta_window", 1, 50);
  r.done();
  try {
    f.validate();
  } catch (const std::invalid_argument& e) {
    r.fail(e.what());
  }
  r.line("normalisation");
  r.check(r.word() == "mean", "expected \"mean\"");
  m.feature_mean = r.nums(kFeatureDim);
  r.check(r.word() == "std", "expected \"std\"");
  m.feature_std = r.nums(kFeatureDim);
  r.check((m.feature_std.array() > 0).all(), "std values must be positive");
  r.done();
  r.line("smoothing");
  m.smoothing.key_rate_hz = r.named_num("key_rate_hz");
  m.smoothing.output_rate_hz = r.named_num("output_rate_hz");
  m.smoothing.noise_deg = r.named_num("noise_deg");
  const double seed = r.named_num("seed");
  r.check(seed >= 0 && seed < 0x1p64 && seed == std::floor(seed),
          "seed: expected a whole number from 0 to 2^64 - 1");
  m.smoothing.seed = static_cast<std::uint64_t>(seed);
  // The bounds of the head's own settings (head.noise_deg, the CLI's
  // --noise-deg); rates up to what a cycle can use.
  r.check(m.smoothing.key_rate_hz > 0 && m.smoothing.key_rate_hz <= 1000 &&
              m.smoothing.output_rate_hz > 0 && m.smoothing.output_rate_hz <= 10000,
          "rates must be above 0 and at most 1000 (key_rate_hz) and 10000 (output_rate_hz)");
  r.check(m.smoothing.noise_deg >= 0 && m.smoothing.noise_deg <= 10,
          "noise_deg must be from 0 to 10");
  r.done();
  r.line("shrink");
  r.check(r.word() == "factor", "expected \"factor\"");
  m.smoothing.shrink = r.nums(3);
  r.check((m.smoothing.shrink.array() >= 0).all() && (m.smoothing.shrink.array() <= 1).all(),
          "factors must be in [0, 1]");
  r.check(r.word() == "toward", "expected \"toward\"");
  m.pose_mean = r.nums(3);
  r.done();
  r.line("decode");
  m.decode.lm_scale = r.named_num("lm_scale");
  m.decode.switch_penalty = r.named_num("switch_penalty");
  r.done();
  r.line("config");
  const int K = r.named_int("K", 1, 4096);
  m.states = r.named_int("S", 1, 64);
  m.mixtures = r.named_int("M", 1, 64);
  const std::string topo = r.named("topology");
  r.check(topo == "LR" || topo == "EG", "topology must be LR or EG, found " + quote(topo));
  m.topology = topo == "LR" ? Topology::kLeftToRight : Topology::kErgodic;
  r.done();
  r.line("utterances");
  const double n_utt = r.num();
  r.check(n_utt >= 0 && n_utt <= std::numeric_limits<int>::max() && n_utt == std::floor(n_utt),
          "expected a count");
  r.done();
  for (int i = 0; i < static_cast<int>(n_utt); ++i) {
    r.line("utterance");
    m.training_utterances.push_back(r.word());
    r.done();
  }
  r.line("codebook");
  r.check(r.named_int("K", 1, 4096) == K, "K differs from the config line");
  const int dim = r.named_int("dim", 3, 3);
  r.done();
  m.codebook.means.resize(K, dim);
  for (int k = 0; k < K; ++k) {
    r.line("cluster");
    r.check(r.num() == k, "expected cluster " + std::to_string(k));
    r.check(r.word() == "mean", "expected \"mean\"");
    m.codebook.means.row(k) = r.nums(dim).transpose();
    r.check(r.word() == "cov", "expected \"cov\"");
    const Eigen::VectorXd c = r.nums(dim * dim);
    const Eigen::MatrixXd cov = Eigen::Map<const Eigen::MatrixXd>(c.data(), dim, dim);
    r.check(cov.isApprox(cov.transpose()) && cov.llt().info() == Eigen::Success,
            "cov must be a symmetric positive-definite matrix");
    m.codebook.covariances.push_back(cov);
    r.done();
  }
  for (int k = 0; k < K; ++k) {
    r.line("hmm");
    r.check(r.num() == k, "expected hmm " + std::to_string(k));
    Hmm h;
    const std::string t = r.named("topology");
    r.check(t == "LR" || t == "EG", "topology must be LR or EG");
    h.topology = t == "LR" ? Topology::kLeftToRight : Topology::kErgodic;
    const int S = r.named_int("states", 1, 64);
    const int M = r.named_int("mixtures", 1, 64);
    r.check(r.named_int("dim", 1, 64) == kFeatureDim,
            "observation dimension must be " + std::to_string(kFeatureDim));
    r.done();
    r.line("pi");
    h.log_pi = r.nums(S);
    r.check(log_probabilities(h.log_pi), kLogProbabilityMessage);
    r.done();
    h.log_a.resize(S, S);
    for (int s = 0; s < S; ++s) {
      r.line("a");
      h.log_a.row(s) = r.nums(S).transpose();
      r.check(log_probabilities(h.log_a.row(s)), kLogProbabilityMessage);
      r.done();
    }
    r.line("exit");
    h.log_exit = r.nums(S);
    r.check(log_probabilities(h.log_exit), kLogProbabilityMessage);
    r.done();
    for (int s = 0; s < S; ++s) {
      GaussianMixture g;
      g.log_weights.resize(M);
      g.means.resize(M, kFeatureDim);
      g.variances.resize(M, kFeatureDim);
      for (int c = 0; c < M; ++c) {
        r.line("mix");
        g.log_weights(c) = r.num();
        r.check(g.log_weights(c) <= kLogOne, kLogProbabilityMessage);
        r.check(r.word() == "mean", "expected \"mean\"");
        g.means.row(c) = r.nums(kFeatureDim).transpose();
        r.check(r.word() == "var", "expected \"var\"");
        g.variances.row(c) = r.nums(kFeatureDim).transpose();
        r.check((g.variances.row(c).array() > 0).all(), "variances must be positive");
        r.done();
      }
      h.states.push_back(std::move(g));
    }
    m.hmms.push_back(std::move(h));
  }
  r.line("bigram");
  r.check(r.word() == "initial", "expected \"initial\"");
  m.bigram.log_initial = r.nums(K);
  r.check(log_probabilities(m.bigram.log_initial), kLogProbabilityMessage);
  r.done();
  m.bigram.log_next.resize(K, K);
  for (int k = 0; k < K; ++k) {
    r.line("next");
    m.bigram.log_next.row(k) = r.nums(K).transpose();
    r.check(log_probabilities(m.bigram.log_next.row(k)), kLogProbabilityMessage);
    r.done();
  }
  r.line("end");
  r.done();
  r.end_of_file();
  return m;
}

}  // namespace animrt::head
