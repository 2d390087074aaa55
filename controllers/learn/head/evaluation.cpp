#include "animrt/learn/head/evaluation.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>

#include "animrt/controllers/head/synthesis.hpp"

namespace animrt::head {
namespace {

Score score(const std::vector<double>& v) {
  Score s;
  if (v.empty()) return s;
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  for (double x : v) s.std += (x - s.mean) * (x - s.mean);
  s.std = v.size() > 1 ? std::sqrt(s.std / static_cast<double>(v.size() - 1)) : 0.0;
  return s;
}

// Pseudo-inverse square root of a covariance.
Eigen::MatrixXd inv_sqrt(const Eigen::MatrixXd& c) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(c);
  const Eigen::VectorXd ev = es.eigenvalues();
  const double top = ev.maxCoeff();
  Eigen::VectorXd d = Eigen::VectorXd::Zero(ev.size());
  for (Eigen::Index i = 0; i < ev.size(); ++i) {
    if (top > 0 && ev(i) > 1e-10 * top) d(i) = 1.0 / std::sqrt(ev(i));
  }
  return es.eigenvectors() * d.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace

double mean_euclidean_deg(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() == 0) return 0.0;
  return (a - b).rowwise().norm().mean();
}

double first_canonical_correlation(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  const Eigen::Index n = x.rows();
  if (n < 2) return 0.0;
  const Eigen::MatrixXd xc = x.rowwise() - x.colwise().mean();
  const Eigen::MatrixXd yc = y.rowwise() - y.colwise().mean();
  const Eigen::MatrixXd sxx = xc.transpose() * xc / static_cast<double>(n - 1);
  const Eigen::MatrixXd syy = yc.transpose() * yc / static_cast<double>(n - 1);
  const Eigen::MatrixXd sxy = xc.transpose() * yc / static_cast<double>(n - 1);
  if (sxx.trace() <= 0 || syy.trace() <= 0) return 0.0;
  const Eigen::MatrixXd m = inv_sqrt(sxx) * sxy * inv_sqrt(syy);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(m);
  return std::min(1.0, svd.singularValues()(0));
}

Eigen::Vector3d mean_pose(const std::vector<PreparedUtterance>& utterances) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double n = 0;
  for (const auto& u : utterances) {
    sum += u.poses.colwise().sum().transpose();
    n += static_cast<double>(u.poses.rows());
  }
  return n > 0 ? Eigen::Vector3d(sum / n) : sum;
}

Evaluation evaluate(const HeadModel& model, const std::vector<PreparedUtterance>& test,
                    const Eigen::Vector3d& baseline_pose) {
  std::vector<double> dist, cca, base, base_cca;
  for (const auto& u : test) {
    const PoseTrack synth = synthesize(model, u.track);
    if (synth.size() < 2) continue;
    // Originals at the output times (linear between feature frames).
    PoseTrack orig;
    for (std::size_t i = 0; i < u.track.size(); ++i) {
      orig.times.push_back(u.track.time(i));
      orig.poses.push_back({u.poses(static_cast<Eigen::Index>(i), 0),
                            u.poses(static_cast<Eigen::Index>(i), 1),
                            u.poses(static_cast<Eigen::Index>(i), 2)});
    }
    Eigen::MatrixXd a(static_cast<Eigen::Index>(synth.size()), 3), b(a.rows(), 3);
    for (std::size_t j = 0; j < synth.size(); ++j) {
      const Euler& s = synth.poses[j];
      const Euler o = orig.at(synth.times[j]);
      a.row(static_cast<Eigen::Index>(j)) << s.yaw, s.pitch, s.roll;
      b.row(static_cast<Eigen::Index>(j)) << o.yaw, o.pitch, o.roll;
    }
    dist.push_back(mean_euclidean_deg(a, b));
    cca.push_back(first_canonical_correlation(a, b));
    Eigen::MatrixXd constant = baseline_pose.transpose().replicate(b.rows(), 1);
    base.push_back(mean_euclidean_deg(constant, b));
    const SmoothingOptions& so = model.smoothing;
    for (Eigen::Index j = 0; j < constant.rows(); ++j) {
      for (int axis = 0; axis < 3; ++axis)
        constant(j, axis) += pose_noise(so.seed, static_cast<std::uint64_t>(j), axis, so.noise_deg);
    }
    base_cca.push_back(first_canonical_correlation(constant, b));
  }
  Evaluation e;
  e.distance_deg = score(dist);
  e.cca = score(cca);
  e.baseline_distance_deg = score(base);
  e.baseline_cca = score(base_cca);
  e.utterances = static_cast<int>(dist.size());
  return e;
}

const std::vector<TableConfig>& paper_table() {
  static const std::vector<TableConfig> rows = {
      {16, 5, 2, Topology::kLeftToRight, 10.2, 3.4, 0.88, 0.11},
      {16, 5, 4, Topology::kLeftToRight, 9.3, 3.4, 0.87, 0.11},
      {16, 3, 2, Topology::kLeftToRight, 9.1, 3.6, 0.87, 0.12},
      {16, 3, 2, Topology::kErgodic, 9.1, 3.4, 0.87, 0.10},
      {16, 3, 4, Topology::kErgodic, 9.5, 3.4, 0.83, 0.12},
      {32, 5, 1, Topology::kLeftToRight, 12.8, 4.0, 0.83, 0.14},
      {32, 3, 2, Topology::kLeftToRight, 10.7, 3.3, 0.86, 0.12},
      {32, 3, 1, Topology::kErgodic, 10.4, 3.1, 0.86, 0.11},
  };
  return rows;
}

std::vector<TableRow> run_table(const std::vector<PreparedUtterance>& train,
                                const std::vector<PreparedUtterance>& test,
                                const FeatureConfig& features, const TrainOptions& base,
                                const std::function<void(const TableRow&)>& on_row) {
  std::vector<TableRow> rows;
  const Eigen::Vector3d baseline = mean_pose(train);
  for (const TableConfig& c : paper_table()) {
    TrainOptions o = base;
    o.clusters = c.clusters;
    o.states = c.states;
    o.mixtures = c.mixtures;
    o.topology = c.topology;
    const HeadModel model = train_model(train, features, o);
    rows.push_back({c, evaluate(model, test, baseline)});
    if (on_row) on_row(rows.back());
  }
  return rows;
}

std::string format_table(const std::vector<TableRow>& rows) {
  std::string out =
      "| HMM config | D mean | D std | CCA mean | CCA std | paper D | paper CCA | mean-pose D | "
      "mean-pose CCA |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  char line[256];
  for (const auto& r : rows) {
    std::snprintf(
        line, sizeof line,
        "| K=%d S=%d M=%d %s | %.1f | %.1f | %.2f | %.2f | %.1f +- %.1f | %.2f +- %.2f | %.1f | "
        "%.2f "
        "|\n",
        r.config.clusters, r.config.states, r.config.mixtures, topology_name(r.config.topology),
        r.result.distance_deg.mean, r.result.distance_deg.std, r.result.cca.mean, r.result.cca.std,
        r.config.paper_distance_mean, r.config.paper_distance_std, r.config.paper_cca_mean,
        r.config.paper_cca_std, r.result.baseline_distance_deg.mean, r.result.baseline_cca.mean);
    out += line;
  }
  return out;
}

}  // namespace animrt::head
