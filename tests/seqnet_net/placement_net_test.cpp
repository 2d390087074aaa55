// Translation carried by the network: a figure of two pieces (a bar, the
// body, and a small sphere held beside its top, the sword) generated and
// completed by a hand-made model whose steps change nothing. With placement
// nodes the walk moves on at the initial frames' velocity and the sword
// keeps its distance to the body; a model without them (an older build's)
// stays where the last initial frame is and lets the sword drift.

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <Eigen/Geometry>
#include <numbers>

#include "animrt/controllers/seqnet/generation.hpp"
#include "animrt/controllers/seqnet/placement_nodes.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/learn/seqnet/network.hpp"
#include "animrt/learn/seqnet/shapes.hpp"

namespace animrt::seqnet {
namespace {

MeshSequence body_and_sword() {
  MeshSequence out = make_bar(4, 6, 4.0);
  const MeshSequence sword = make_icosphere(0);
  const int v = out.vertex_count();
  Positions all(3, v + sword.vertex_count());
  all.leftCols(v) = out.frames.front();
  all.rightCols(sword.vertex_count()) =
      (0.3 * sword.frames.front()).colwise() + Eigen::Vector3d(1.6, 0.0, 3.5);
  for (auto t : sword.triangles) out.triangles.push_back({t[0] + v, t[1] + v, t[2] + v});
  out.frames = {all};
  return out;
}

// Every parameter 0: dX = 0 whatever the input and state.
ModelFile still_model(const MeshSequence& figure, int placement_nodes) {
  torch::manual_seed(3);
  ModelFile m;
  m.shape.kind = ModelKind::mesh;
  m.shape.vertex_count = figure.vertex_count();
  m.shape.placement_nodes = placement_nodes;
  m.shape.channels = 3;
  m.shape.latent = 4;
  m.shape.hidden = 6;
  m.shape.window = 8;
  m.rest = figure.frames.front();
  m.triangles = figure.triangles;
  m.low.assign(static_cast<std::size_t>(m.shape.input_dims()), -4.0);
  m.high.assign(static_cast<std::size_t>(m.shape.input_dims()), 4.0);
  SeqNet net(m.shape, mesh_graph(m.shape.vertex_count, m.triangles));
  m.parameters = save_parameters(*net);
  for (NamedArray& a : m.parameters) std::fill(a.values.begin(), a.values.end(), 0.0F);
  return m;
}

Positions moved(const Positions& p, double angle, const Eigen::Vector3d& shift) {
  const Eigen::Vector3d pivot(0.0, 0.0, 2.0);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return ((r * (p.colwise() - pivot)).colwise() + pivot).colwise() + shift;
}

double diagonal(const Positions& p) {
  return (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).norm();
}

// The sword's centroid to the body vertex nearest it in the template (the
// hand), and to the body's centroid.
Eigen::Vector2d sword_distances(const Positions& p, int body_vertices) {
  static const Positions rest = body_and_sword().frames[0];
  const Eigen::Vector3d held = rest.rightCols(rest.cols() - body_vertices).rowwise().mean();
  Eigen::Index hand = 0;
  (rest.leftCols(body_vertices).colwise() - held).colwise().squaredNorm().minCoeff(&hand);
  const Eigen::Vector3d sword = p.rightCols(p.cols() - body_vertices).rowwise().mean();
  const Eigen::Vector3d body = p.leftCols(body_vertices).rowwise().mean();
  return {(sword - p.col(hand)).norm(), (sword - body).norm()};
}

class SeqPlacementNet : public ::testing::Test {
 protected:
  MeshSequence figure_ = body_and_sword();
  int body_ = make_bar(4, 6, 4.0).vertex_count();
  int nodes_ =
      placement_layout(build_neighbourhood(figure_.frames[0], figure_.triangles), figure_.frames[0])
          .nodes;
};

TEST_F(SeqPlacementNet, GeneratedFramesWalkOnWithTheSwordInPlace) {
  ASSERT_EQ(nodes_, 1);  // velocity and one piece's offset: 6 of 9 numbers
  const Eigen::Vector3d step(0.2, 0.05, 0.0);
  const Positions first = moved(figure_.frames[0], 0.5, Eigen::Vector3d::Zero());
  const Positions second = moved(figure_.frames[0], 0.5, step);
  const double tolerance = 0.01 * diagonal(first);
  GenerateOptions o;
  o.frames = 5;
  const ModelFile model = still_model(figure_, nodes_);
  const auto out = generate_mesh(model, "m.model", {first, second}, figure_.triangles, o);
  ASSERT_EQ(out.size(), 7U);
  for (int k = 2; k < 7; ++k) {
    const Positions want = moved(figure_.frames[0], 0.5, step * k);
    EXPECT_LT((out[static_cast<std::size_t>(k)] - want).colwise().norm().maxCoeff(), tolerance)
        << k;
    EXPECT_LT((sword_distances(out[static_cast<std::size_t>(k)], body_) -
               sword_distances(figure_.frames[0], body_))
                  .cwiseAbs()
                  .maxCoeff(),
              tolerance)
        << k;
  }
  // Without placement nodes the figure stays where the last initial frame is.
  const auto old =
      generate_mesh(still_model(figure_, 0), "m.model", {first, second}, figure_.triangles, o);
  const Positions want = moved(figure_.frames[0], 0.5, step * 6);
  EXPECT_GT((old.back() - want).colwise().norm().maxCoeff(), tolerance);
}

TEST_F(SeqPlacementNet, CompletedFramesKeepTheSwordInItsHandAndMoveTheBody) {
  const Positions a = figure_.frames[0];
  const Eigen::Vector3d shift(0.5, 0.0, 0.0);
  const Positions b = moved(a, 0.5 * std::numbers::pi, shift);
  const double tolerance = 0.01 * diagonal(a);
  const int gap = 4;
  const CompletionOptions options{.threshold = 0.05, .retries = 0, .seed = 1};
  const auto complete = [&](const ModelFile& model) {
    const FrameMatrix keys = mesh_features(model, "m.model", {a, b}, figure_.triangles, gap + 1.0);
    SeqNetInference net(model, "m.model");
    return completed_mesh(model, {a, b}, keys, net.complete(keys, {gap}, options), gap);
  };
  const auto out = complete(still_model(figure_, nodes_));
  ASSERT_EQ(out.size(), 6U);
  const Eigen::Vector2d held = sword_distances(a, body_);
  double worst_old = 0.0;
  const auto old = complete(still_model(figure_, 0));
  for (int t = 1; t <= gap; ++t) {
    const Positions& p = out[static_cast<std::size_t>(t)];
    EXPECT_LT((sword_distances(p, body_) - held).cwiseAbs().maxCoeff(), tolerance) << t;
    // The body's centroid moves on a straight line from key to key.
    const Eigen::Vector3d body = p.leftCols(body_).rowwise().mean();
    const Eigen::Vector3d line = a.leftCols(body_).rowwise().mean() + shift * (t / (gap + 1.0));
    EXPECT_LT((body - line).norm(), 1e-6) << t;
    worst_old = std::max(
        worst_old,
        (sword_distances(old[static_cast<std::size_t>(t)], body_) - held).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(worst_old, tolerance);  // blended key offsets let the sword drift
}

}  // namespace
}  // namespace animrt::seqnet
