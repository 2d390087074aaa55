// Building and posing the skin (see skin.hpp).

#include "animrt/learn/seq_corpus/skin.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "animrt/learn/seq_corpus/body_field.hpp"

namespace animrt::learn::seq_corpus {
namespace {

// Tries of the grid step, each corrected by how far the vertex count missed.
constexpr int kStepTries = 3;
constexpr double kCountTolerance = 0.25;
// The fine surface: this many times the vertices asked for, at least.
constexpr int kFineFactor = 6;
constexpr int kFineMinVertices = 20000;
// Limbs at least this many grid steps thick (so the grid samples them all),
// segments blended over this many steps.
constexpr double kMinThicknessSteps = 0.9;
constexpr double kBlendSteps = 1.0;
// Grid margin around the bodies, in steps.
constexpr double kMarginSteps = 2.5;

TriangleMesh surface(const mjModel* m, const mjData* d, double step) {
  const BodyField field(m, d, kMinThicknessSteps * step, kBlendSteps * step);
  Eigen::AlignedBox3d box = field.bounds();
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(kMarginSteps * step);
  box = Eigen::AlignedBox3d(box.min() - margin, box.max() + margin);
  return largest_component(marching_tetrahedra(
      [&field](const Eigen::Vector3d& p) { return field.distance(p); }, box, step));
}

Eigen::Matrix3d body_rot(const mjData* d, int b) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->xmat + 9 * b);
}

}  // namespace

Skin build_skin(const mjModel* m, const mjData* d, const SkinOptions& options) {
  const int target = std::max(options.target_vertices, 50);
  // A fine surface first, with every limb resolved, then decimated to the
  // count asked for: a grid coarse enough to give a few hundred vertices
  // directly would turn the legs into blobs.
  const int fine_target = std::max(kFineFactor * target, kFineMinVertices);
  // First guess from the bodies' box; the count grows as 1 / step^2.
  const BodyField probe(m, d, 0.0, 0.0);
  double step = probe.bounds().sizes().norm() / 60.0;
  Skin skin;
  for (int attempt = 0; attempt < kStepTries; ++attempt) {
    skin.rest = surface(m, d, step);
    skin.grid_step_m = step;
    const int count = static_cast<int>(skin.rest.vertices.cols());
    if (std::fabs(std::log(std::max(count, 1) / static_cast<double>(fine_target))) <
        kCountTolerance)
      break;
    step *= std::sqrt(std::max(count, 1) / static_cast<double>(fine_target));
  }
  if (skin.rest.vertices.cols() > target) skin.rest = decimate(skin.rest, target);
  const MeshReport report = check_mesh(skin.rest, 1e-6 * skin.grid_step_m * skin.grid_step_m);
  if (!report.closed_manifold() || report.components != 1 || report.degenerate > 0) {
    throw std::runtime_error("skin surface is not one closed manifold (" +
                             std::to_string(report.boundary_edges) + " boundary, " +
                             std::to_string(report.nonmanifold_edges) + " non-manifold edges)");
  }

  // Weights: inverse square distance to the nearest bodies, the softening
  // one grid step so a vertex on a body's surface still blends with a
  // neighbour that is as close.
  const BodyField field(m, d, kMinThicknessSteps * skin.grid_step_m, 0.0);
  const double soft = skin.grid_step_m;
  const auto& bodies = field.bodies();
  const int n = static_cast<int>(skin.rest.vertices.cols());
  skin.bodies.resize(static_cast<std::size_t>(n));
  skin.weights.resize(static_cast<std::size_t>(n));
  std::vector<double> dist;
  std::vector<int> order(bodies.size());
  for (int v = 0; v < n; ++v) {
    field.body_distances(skin.rest.vertices.col(v), dist);
    std::iota(order.begin(), order.end(), 0);
    const std::size_t k = std::min<std::size_t>(kInfluences, bodies.size());
    std::partial_sort(order.begin(), order.begin() + static_cast<long>(k), order.end(),
                      [&dist](int a, int b) {
                        const double da = dist[static_cast<std::size_t>(a)];
                        const double db = dist[static_cast<std::size_t>(b)];
                        return da != db ? da < db : a < b;
                      });
    auto& ids = skin.bodies[static_cast<std::size_t>(v)];
    auto& w = skin.weights[static_cast<std::size_t>(v)];
    ids.fill(0);
    w.fill(0.0);
    double sum = 0.0;
    for (std::size_t i = 0; i < k; ++i) {
      const double dd = std::max(dist[static_cast<std::size_t>(order[i])], 0.0) + soft;
      ids[i] = bodies[static_cast<std::size_t>(order[i])];
      w[i] = 1.0 / (dd * dd);
      sum += w[i];
    }
    for (std::size_t i = 0; i < k; ++i) w[i] /= sum;
  }
  skin.bind_pos.resize(static_cast<std::size_t>(m->nbody));
  skin.bind_rot.resize(static_cast<std::size_t>(m->nbody));
  for (int b = 0; b < m->nbody; ++b) {
    skin.bind_pos[static_cast<std::size_t>(b)] = Eigen::Vector3d(d->xpos + 3 * b);
    skin.bind_rot[static_cast<std::size_t>(b)] = body_rot(d, b);
  }
  return skin;
}

void pose_skin(const Skin& skin, const mjData* d, seqnet::Positions& out) {
  const auto nb = skin.bind_pos.size();
  // Each body's motion since the bind pose: x -> A x + t.
  std::vector<Eigen::Matrix3d> a(nb);
  std::vector<Eigen::Vector3d> t(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    a[b] = body_rot(d, static_cast<int>(b)) * skin.bind_rot[b].transpose();
    t[b] = Eigen::Vector3d(d->xpos + 3 * b) - a[b] * skin.bind_pos[b];
  }
  const Eigen::Index n = skin.rest.vertices.cols();
  out.resize(3, n);
  for (Eigen::Index v = 0; v < n; ++v) {
    const Eigen::Vector3d x = skin.rest.vertices.col(v);
    Eigen::Vector3d y = Eigen::Vector3d::Zero();
    const auto& ids = skin.bodies[static_cast<std::size_t>(v)];
    const auto& w = skin.weights[static_cast<std::size_t>(v)];
    for (int i = 0; i < kInfluences; ++i) {
      if (w[static_cast<std::size_t>(i)] == 0.0) continue;
      const auto b = static_cast<std::size_t>(ids[static_cast<std::size_t>(i)]);
      y += w[static_cast<std::size_t>(i)] * (a[b] * x + t[b]);
    }
    out.col(v) = y;
  }
}

int dominant_body(const Skin& skin, int v) {
  const auto& w = skin.weights[static_cast<std::size_t>(v)];
  const auto i = static_cast<std::size_t>(std::max_element(w.begin(), w.end()) - w.begin());
  return skin.bodies[static_cast<std::size_t>(v)][i];
}

}  // namespace animrt::learn::seq_corpus
