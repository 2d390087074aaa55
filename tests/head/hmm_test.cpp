// HMMs against hand-worked numbers; Baum-Welch; network decoding.

#include "animrt/controllers/head/hmm.hpp"

#include <gtest/gtest.h>

#include <random>

#include "animrt/controllers/head/decoder.hpp"
#include "animrt/learn/head/bigram_training.hpp"
#include "animrt/learn/head/hmm_training.hpp"

namespace animrt::head {
namespace {

// Two states, pi = (0.6, 0.4), A = [0.7 0.3; 0.4 0.6], exit 1 (no end
// constraint), and emission probabilities given directly.
Hmm two_state() {
  Hmm h;
  h.topology = Topology::kErgodic;
  h.log_pi = Eigen::Vector2d(0.6, 0.4).array().log();
  h.log_a.resize(2, 2);
  h.log_a << 0.7, 0.3, 0.4, 0.6;
  h.log_a = h.log_a.array().log();
  h.log_exit = Eigen::Vector2d::Zero();
  h.states.resize(2);
  return h;
}

Eigen::MatrixXd emissions() {
  Eigen::MatrixXd b(3, 2);
  b << 0.5, 0.1, 0.4, 0.3, 0.1, 0.6;
  return b.array().log();
}

TEST(Hmm, ForwardMatchesHandWorkedExample) {
  Eigen::MatrixXd la;
  const double lp = forward(two_state(), emissions(), la);
  // alpha_1 = (0.3, 0.04); alpha_2 = (0.0904, 0.0342); alpha_3 = (0.007696, 0.028584)
  EXPECT_NEAR(std::exp(la(0, 0)), 0.3, 1e-12);
  EXPECT_NEAR(std::exp(la(1, 0)), 0.0904, 1e-12);
  EXPECT_NEAR(std::exp(la(1, 1)), 0.0342, 1e-12);
  EXPECT_NEAR(std::exp(la(2, 0)), 0.007696, 1e-12);
  EXPECT_NEAR(std::exp(la(2, 1)), 0.028584, 1e-12);
  EXPECT_NEAR(std::exp(lp), 0.03628, 1e-12);
}

TEST(Hmm, BackwardAgreesAndPosteriorsSumToOne) {
  Eigen::MatrixXd la, lb;
  const double pf = forward(two_state(), emissions(), la);
  const double pb = backward(two_state(), emissions(), lb);
  EXPECT_NEAR(pf, pb, 1e-12);
  // beta_2 = A * (b_3 .* beta_3) = (0.7*0.1 + 0.3*0.6, 0.4*0.1 + 0.6*0.6) = (0.25, 0.4)
  EXPECT_NEAR(std::exp(lb(1, 0)), 0.25, 1e-12);
  EXPECT_NEAR(std::exp(lb(1, 1)), 0.4, 1e-12);
  for (int t = 0; t < 3; ++t)
    EXPECT_NEAR((la.row(t) + lb.row(t)).array().exp().sum() / std::exp(pf), 1.0, 1e-12);
}

TEST(Hmm, ViterbiMatchesHandWorkedExample) {
  std::vector<int> path;
  const double lp = viterbi(two_state(), emissions(), path);
  // delta_3 = (0.00588, 0.01512) via 0 -> 0 -> 1.
  EXPECT_EQ(path, (std::vector<int>{0, 0, 1}));
  EXPECT_NEAR(std::exp(lp), 0.01512, 1e-12);
}

TEST(Hmm, ExitConstraintOfLeftToRight) {
  Hmm h = two_state();
  h.log_pi << 0, kLogZero;
  h.log_a << std::log(0.5), std::log(0.5), kLogZero, 0;
  h.log_exit << kLogZero, 0;
  std::vector<int> path;
  viterbi(h, emissions(), path);
  EXPECT_EQ(path.front(), 0);
  EXPECT_EQ(path.back(), 1);
  Eigen::MatrixXd la;
  Eigen::MatrixXd one = emissions().topRows(1);
  EXPECT_EQ(forward(h, one, la), kLogZero);  // one frame cannot cross two states
}

TEST(Hmm, GaussianMixtureDensity) {
  GaussianMixture g;
  g.log_weights = Eigen::Vector2d(0.25, 0.75).array().log();
  g.means.resize(2, 1);
  g.means << 0, 2;
  g.variances.resize(2, 1);
  g.variances << 1, 4;
  Eigen::VectorXd x(1);
  x << 1;
  const double expected =
      0.25 * std::exp(-0.5) / std::sqrt(2 * M_PI) + 0.75 * std::exp(-0.125) / std::sqrt(8 * M_PI);
  EXPECT_NEAR(g.log_density(x), std::log(expected), 1e-12);
}

// Sequences from a 2-state left-to-right model in 2-D.
std::vector<Eigen::MatrixXd> lr_sequences(int count, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  std::uniform_int_distribution<int> len(4, 12);
  std::vector<Eigen::MatrixXd> out;
  for (int s = 0; s < count; ++s) {
    const int a = len(rng), b = len(rng);
    Eigen::MatrixXd x(a + b, 2);
    for (int t = 0; t < a + b; ++t) {
      const bool second = t >= a;
      x.row(t) << (second ? 3.0 : -1.0) + n(rng), (second ? -2.0 : 1.0) + 0.5 * n(rng);
    }
    out.push_back(x);
  }
  return out;
}

TEST(Hmm, BaumWelchIncreasesLikelihoodAndKeepsTopology) {
  std::mt19937_64 rng(11);
  const auto seqs = lr_sequences(30, rng);
  for (Topology topo : {Topology::kLeftToRight, Topology::kErgodic}) {
    HmmTrainOptions o;
    o.states = 3;
    o.mixtures = 2;
    o.topology = topo;
    o.max_iterations = 15;
    o.tolerance = 0;
    Hmm h = init_hmm(seqs, o);
    const auto history = baum_welch(h, seqs, o);
    ASSERT_GE(history.size(), 3u);
    for (std::size_t i = 1; i < history.size(); ++i)
      EXPECT_GE(history[i], history[i - 1] - 1e-6) << i;
    EXPECT_GT(history.back(), history.front() + 1.0);
    for (int s = 0; s < 3; ++s) {
      EXPECT_NEAR(std::exp(h.log_exit(s)) + h.log_a.row(s).array().exp().sum(), 1.0, 1e-9);
    }
    if (topo == Topology::kLeftToRight) {
      EXPECT_EQ(h.log_a(1, 0), kLogZero);
      EXPECT_EQ(h.log_a(0, 2), kLogZero);
      EXPECT_EQ(h.log_exit(0), kLogZero);
      EXPECT_EQ(h.log_pi(1), kLogZero);
    }
  }
}

// Two single-state cluster models, observations from cluster 0 then 1.
TEST(Decoder, NetworkViterbiFindsTheClusterSequence) {
  auto model = [](double mean) {
    Hmm h;
    h.topology = Topology::kLeftToRight;
    h.log_pi = Eigen::VectorXd::Zero(1);
    h.log_a = Eigen::MatrixXd::Constant(1, 1, std::log(0.9));
    h.log_exit = Eigen::VectorXd::Constant(1, std::log(0.1));
    GaussianMixture g;
    g.log_weights = Eigen::VectorXd::Zero(1);
    g.means = Eigen::MatrixXd::Constant(1, 1, mean);
    g.variances = Eigen::MatrixXd::Ones(1, 1);
    h.states.push_back(g);
    return h;
  };
  const std::vector<Hmm> hmms = {model(-2), model(2)};
  const Bigram bigram = train_bigram({{0, 1}, {1, 0}}, 2);
  std::mt19937_64 rng(2);
  std::normal_distribution<double> n(0, 0.7);
  Eigen::MatrixXd obs(60, 1);
  for (int t = 0; t < 60; ++t) obs(t, 0) = (t < 25 ? -2.0 : 2.0) + n(rng);
  const std::vector<int> c = decode_clusters(hmms, bigram, DecodeOptions{1.0, 0.0}, obs);
  ASSERT_EQ(c.size(), 60u);
  int errors = 0;
  for (int t = 0; t < 60; ++t) errors += c[static_cast<std::size_t>(t)] != (t < 25 ? 0 : 1);
  EXPECT_LE(errors, 2);
  // A strong switch penalty keeps one cluster throughout.
  const std::vector<int> stuck = decode_clusters(hmms, bigram, DecodeOptions{1.0, -1e6}, obs);
  EXPECT_EQ(collapse_runs(stuck).size(), 1u);

  // Fixed lag: with a lag as long as the input the result is the offline one;
  // with a short lag it commits as it goes and still follows the switch.
  for (int lag : {60, 8}) {
    NetworkDecoder d(hmms, bigram, DecodeOptions{1.0, 0.0}, lag);
    std::vector<int> out;
    int k = 0;
    for (int t = 0; t < 60; ++t) {
      if (d.push(obs.row(t).transpose(), k)) out.push_back(k);
    }
    EXPECT_EQ(static_cast<int>(out.size()), std::max(0, 60 - lag));
    d.finish(out);
    ASSERT_EQ(out.size(), 60u);
    int diff = 0;
    for (std::size_t t = 0; t < 60; ++t) diff += out[t] != c[t];
    if (lag == 60) {
      EXPECT_EQ(diff, 0);
    } else {
      EXPECT_LE(diff, 3);
    }
  }
}

}  // namespace
}  // namespace animrt::head
