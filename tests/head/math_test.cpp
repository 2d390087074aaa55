// Spline fill, LBG, bigram smoothing, SQUAD, rotations, CCA.

#include <gtest/gtest.h>

#include <random>

#include "animrt/controllers/head/bigram.hpp"
#include "animrt/controllers/head/rotation.hpp"
#include "animrt/controllers/head/spline.hpp"
#include "animrt/controllers/head/squad.hpp"
#include "animrt/controllers/head/vq.hpp"
#include "animrt/learn/head/bigram_training.hpp"
#include "animrt/learn/head/evaluation.hpp"
#include "animrt/learn/head/lbg.hpp"

namespace animrt::head {
namespace {

TEST(Spline, PassesThroughKnotsAndReproducesLines) {
  const NaturalCubicSpline s({0, 1, 3, 4}, {1, 3, 7, 9});  // y = 2x + 1
  for (double x : {0.0, 0.5, 1.7, 2.2, 3.9}) EXPECT_NEAR(s(x), 2 * x + 1, 1e-12);
  const NaturalCubicSpline c({0, 1, 2, 5}, {0, 4, -1, 2});
  EXPECT_NEAR(c(1), 4, 1e-12);
  EXPECT_NEAR(c(2), -1, 1e-12);
  EXPECT_EQ(c(-3), 0);  // held outside
  EXPECT_EQ(c(9), 2);
}

TEST(Spline, FillsGapsSmoothlyAndClamps) {
  std::vector<double> v(40);
  std::unique_ptr<bool[]> known(new bool[40]);
  for (int i = 0; i < 40; ++i) {
    v[static_cast<std::size_t>(i)] = 100 + 20 * std::sin(i / 8.0);
    known[i] = i < 12 || i > 25;
  }
  std::vector<double> holes = v;
  for (int i = 12; i <= 25; ++i) holes[static_cast<std::size_t>(i)] = 0;
  const auto filled = fill_gaps_spline(holes, std::span<const bool>(known.get(), 40), 80, 500);
  for (int i = 0; i < 40; ++i)
    EXPECT_NEAR(filled[static_cast<std::size_t>(i)], v[static_cast<std::size_t>(i)], 3.0) << i;
  for (int i = 0; i < 40; ++i) {
    if (known[i]) {
      EXPECT_EQ(filled[static_cast<std::size_t>(i)], v[static_cast<std::size_t>(i)]);
    }
  }
  const auto clamped = fill_gaps_spline(holes, std::span<const bool>(known.get(), 40), 80, 105);
  for (int i = 12; i <= 25; ++i) EXPECT_LE(clamped[static_cast<std::size_t>(i)], 105);
}

TEST(Lbg, FindsSeparableClusters) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 0.5);
  const Eigen::Vector3d centres[4] = {{-10, 0, 0}, {10, 0, 0}, {0, 10, 5}, {0, -10, -5}};
  Eigen::MatrixXd data(400, 3);
  for (int i = 0; i < 400; ++i)
    data.row(i) = (centres[i % 4] + Eigen::Vector3d(n(rng), n(rng), n(rng))).transpose();
  const Codebook book = train_lbg(data, 4);
  ASSERT_EQ(book.size(), 4);
  for (const auto& c : centres) {
    const int k = book.nearest(c);
    EXPECT_LT((book.means.row(k).transpose() - c).norm(), 0.2);
    EXPECT_NEAR(book.covariances[static_cast<std::size_t>(k)](0, 0), 0.25, 0.1);
  }
  // Every point goes to the code vector of its own centre.
  for (int i = 0; i < 400; ++i)
    EXPECT_EQ(book.nearest(data.row(i).transpose()), book.nearest(centres[i % 4]));
  EXPECT_LT(distortion(book, data), 1.0);
  // Not a power of two.
  EXPECT_EQ(train_lbg(data, 3).size(), 3);
  EXPECT_EQ(train_lbg(data, 6).size(), 6);
}

TEST(Bigram, SmoothsUnseenPairsAndNormalises) {
  const Bigram b = train_bigram({{0, 0, 1, 1, 2}, {0, 1, 2, 1}}, 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(b.log_next.row(i).array().exp().sum(), 1.0, 1e-12);
    for (int j = 0; j < 4; ++j) EXPECT_GT(b.log_next(i, j), -1e9);
  }
  EXPECT_NEAR(b.log_initial.array().exp().sum(), 1.0, 1e-12);
  EXPECT_GT(b.log_next(0, 1), b.log_next(0, 2));  // seen twice vs never
  EXPECT_GT(b.log_next(1, 2), b.log_next(1, 3));
  EXPECT_GT(b.log_initial(0), b.log_initial(1));
  // Cluster 3 never occurs: its row is the unigram.
  EXPECT_GT(b.log_next(3, 1), b.log_next(3, 3));
  EXPECT_EQ(collapse_runs({3, 3, 1, 1, 1, 3}), (std::vector<int>{3, 1, 3}));
}

Eigen::Quaterniond q_of(double y, double p, double r) { return euler_to_quat({y, p, r}); }

TEST(Squad, PassesThroughKeysStaysUnitAndContinuous) {
  std::vector<Eigen::Quaterniond> keys = {q_of(0, 0, 0), q_of(10, -5, 2), q_of(-5, 8, 0),
                                          q_of(20, 0, -6), q_of(0, 3, 3)};
  const SquadCurve c(keys);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    EXPECT_NEAR(std::abs(c(static_cast<double>(i)).dot(keys[i])), 1.0, 1e-9);
  }
  Eigen::Quaterniond prev = c(0);
  double max_step = 0;
  for (int i = 1; i <= 400; ++i) {
    const Eigen::Quaterniond q = c(i / 100.0);
    EXPECT_NEAR(q.norm(), 1.0, 1e-9);
    max_step = std::max(max_step, q.angularDistance(prev));
    prev = q;
  }
  EXPECT_LT(max_step, 0.01);  // no jumps (radians per 1/100 key)
}

TEST(Squad, SignFlipsChangeNothing) {
  std::vector<Eigen::Quaterniond> keys = {q_of(0, 0, 0), q_of(30, 5, 0), q_of(60, -5, 4),
                                          q_of(40, 0, 0)};
  std::vector<Eigen::Quaterniond> flipped = keys;
  flipped[1].coeffs() *= -1;
  flipped[3].coeffs() *= -1;
  const SquadCurve a(keys), b(flipped);
  for (int i = 0; i <= 30; ++i) {
    EXPECT_LT(a(i / 10.0).angularDistance(b(i / 10.0)), 1e-9);
  }
  // Consistent signs along the chain.
  for (std::size_t i = 1; i < b.keys().size(); ++i)
    EXPECT_GE(b.keys()[i - 1].dot(b.keys()[i]), 0.0);
  // Interpolating between q and -q does not swing round: it stays put.
  const Eigen::Quaterniond q = q_of(10, 0, 0);
  Eigen::Quaterniond neg = q;
  neg.coeffs() *= -1;
  EXPECT_LT(slerp(q, neg, 0.5).angularDistance(q), 1e-9);
}

TEST(Rotation, EulerRoundTripAndConventions) {
  const Euler e{20, -15, 7};
  const Euler back = quat_to_euler(euler_to_quat(e));
  EXPECT_NEAR(back.yaw, 20, 1e-9);
  EXPECT_NEAR(back.pitch, -15, 1e-9);
  EXPECT_NEAR(back.roll, 7, 1e-9);
  // Positive pitch tips the nose (x forward) down.
  EXPECT_LT((euler_to_matrix({0, 20, 0}) * Eigen::Vector3d::UnitX()).z(), 0);
  // Positive yaw turns the face to its left (+y).
  EXPECT_GT((euler_to_matrix({20, 0, 0}) * Eigen::Vector3d::UnitX()).y(), 0);
}

TEST(Rotation, SvdRecoversTheRotationOfAMarkerSet) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0, 1), tiny(0, 1e-4);
  Eigen::MatrixX3d ref(8, 3);
  for (int i = 0; i < 8; ++i) ref.row(i) << n(rng), n(rng), n(rng);
  ref.rowwise() -= ref.colwise().mean();
  for (const Euler& e : {Euler{0, 0, 0}, Euler{25, -10, 5}, Euler{-40, 30, -20}, Euler{5, 2, 60}}) {
    const Eigen::Matrix3d r = euler_to_matrix(e);
    Eigen::MatrixX3d frame = (r * ref.transpose()).transpose();
    for (int i = 0; i < 8; ++i) frame.row(i) += Eigen::RowVector3d(tiny(rng), tiny(rng), tiny(rng));
    const Euler got = matrix_to_euler(rotation_from_markers(ref, frame));
    EXPECT_NEAR(got.yaw, e.yaw, 0.01);
    EXPECT_NEAR(got.pitch, e.pitch, 0.01);
    EXPECT_NEAR(got.roll, e.roll, 0.01);
  }
  // Coplanar markers (a reflection fits as well as the rotation): still a rotation.
  Eigen::MatrixX3d flat(4, 3);
  flat << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0;
  const Eigen::Matrix3d r = euler_to_matrix({30, 0, 0});
  const Eigen::Matrix3d got = rotation_from_markers(flat, (r * flat.transpose()).transpose());
  EXPECT_NEAR(got.determinant(), 1.0, 1e-9);
  EXPECT_LT((got - r).norm(), 1e-9);
}

TEST(Measures, CanonicalCorrelationOnKnownData) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0, 1);
  const int N = 4000;
  Eigen::MatrixXd x(N, 3), y(N, 3), indep(N, 3), half(N, 1), other(N, 1);
  for (int i = 0; i < N; ++i) {
    x.row(i) << n(rng), n(rng), n(rng);
    indep.row(i) << n(rng), n(rng), n(rng);
    const double z = n(rng);
    half(i, 0) = z + n(rng);
    other(i, 0) = z + n(rng);
  }
  Eigen::Matrix3d a;
  a << 1, 2, 0, 0, 1, -1, 3, 0, 1;
  y = x * a;
  EXPECT_NEAR(first_canonical_correlation(x, y), 1.0, 1e-9);
  EXPECT_LT(first_canonical_correlation(x, indep), 0.1);
  EXPECT_NEAR(first_canonical_correlation(half, other), 0.5,
              0.05);  // var(z) / (var(z) + var(noise))
  EXPECT_EQ(first_canonical_correlation(x, Eigen::MatrixXd::Ones(N, 3)), 0.0);

  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(2, 3), q(2, 3);
  q << 3, 4, 0, 0, 0, 1;
  EXPECT_DOUBLE_EQ(mean_euclidean_deg(p, q), 3.0);
}

}  // namespace
}  // namespace animrt::head
