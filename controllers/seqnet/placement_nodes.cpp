#include "animrt/controllers/seqnet/placement_nodes.hpp"

#include <limits>
#include <stdexcept>

#include "animrt/controllers/seqnet/reconstruction.hpp"

namespace animrt::seqnet {
namespace {

std::vector<Eigen::Vector3d> piece_centroids(const Neighbourhood& ring, const Positions& frame) {
  std::vector<Eigen::Vector3d> sum(static_cast<std::size_t>(ring.piece_count),
                                   Eigen::Vector3d::Zero());
  std::vector<int> size(static_cast<std::size_t>(ring.piece_count), 0);
  for (int i = 0; i < ring.vertex_count; ++i) {
    sum[static_cast<std::size_t>(ring.piece[i])] += frame.col(i);
    ++size[static_cast<std::size_t>(ring.piece[i])];
  }
  for (std::size_t p = 0; p < sum.size(); ++p) sum[p] /= std::max(1, size[p]);
  return sum;
}

Eigen::Matrix3d anchor_rotation(const FeatureFrame& raw, int vertex) {
  return rotation_exp(raw.col(vertex).head<3>());
}

}  // namespace

PlacementLayout placement_layout(const Neighbourhood& ring, const Positions& rest) {
  PlacementLayout l;
  std::vector<int> size(static_cast<std::size_t>(ring.piece_count), 0);
  for (int i = 0; i < ring.vertex_count; ++i) ++size[static_cast<std::size_t>(ring.piece[i])];
  for (int p = 1; p < ring.piece_count; ++p) {
    if (size[static_cast<std::size_t>(p)] > size[static_cast<std::size_t>(l.body)]) l.body = p;
  }
  const std::vector<Eigen::Vector3d> c = piece_centroids(ring, rest);
  l.anchor.assign(static_cast<std::size_t>(ring.piece_count), -1);
  for (int p = 0; p < ring.piece_count; ++p) {
    if (p == l.body) continue;
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < ring.vertex_count; ++i) {
      if (ring.piece[i] != l.body) continue;
      const double d = (rest.col(i) - c[static_cast<std::size_t>(p)]).squaredNorm();
      if (d < best) {
        best = d;
        l.anchor[static_cast<std::size_t>(p)] = i;
      }
    }
  }
  l.nodes = (3 * std::max(1, ring.piece_count) + 8) / 9;
  return l;
}

Eigen::Vector3d body_centroid(const PlacementLayout& layout, const Neighbourhood& ring,
                              const Positions& frame) {
  return piece_centroids(ring, frame)[static_cast<std::size_t>(layout.body)];
}

Eigen::VectorXd placement_values(const PlacementLayout& layout, const Neighbourhood& ring,
                                 const Positions& frame, const FeatureFrame& raw,
                                 const Eigen::Vector3d& velocity) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(layout.values());
  out.head<3>() = velocity;
  const std::vector<Eigen::Vector3d> c = piece_centroids(ring, frame);
  int at = 3;
  for (int p = 0; p < ring.piece_count; ++p) {
    const int a = layout.anchor[static_cast<std::size_t>(p)];
    if (a < 0) continue;
    out.segment<3>(at) =
        anchor_rotation(raw, a).transpose() * (c[static_cast<std::size_t>(p)] - frame.col(a));
    at += 3;
  }
  return out;
}

void place_by_values(const PlacementLayout& layout, const Neighbourhood& ring, Positions& frame,
                     const FeatureFrame& raw, const Eigen::VectorXd& values,
                     const Eigen::Vector3d& centroid) {
  if (values.size() != layout.values()) throw std::invalid_argument("place_by_values: size");
  const std::vector<Eigen::Vector3d> c = piece_centroids(ring, frame);
  std::vector<Eigen::Vector3d> shift(c.size(), Eigen::Vector3d::Zero());
  shift[static_cast<std::size_t>(layout.body)] =
      centroid - c[static_cast<std::size_t>(layout.body)];
  // Anchors are body vertices: where they are once the body is placed.
  const Eigen::Vector3d body_shift = shift[static_cast<std::size_t>(layout.body)];
  int at = 3;
  for (int p = 0; p < ring.piece_count; ++p) {
    const int a = layout.anchor[static_cast<std::size_t>(p)];
    if (a < 0) continue;
    const Eigen::Vector3d want =
        frame.col(a) + body_shift + anchor_rotation(raw, a) * values.segment<3>(at);
    shift[static_cast<std::size_t>(p)] = want - c[static_cast<std::size_t>(p)];
    at += 3;
  }
  for (int i = 0; i < ring.vertex_count; ++i) {
    frame.col(i) += shift[static_cast<std::size_t>(ring.piece[i])];
  }
}

std::vector<Eigen::VectorXd> placement_track(const SequenceFeatures& f) {
  if (f.placement.empty()) return {};
  const std::vector<Positions> frames = reconstruct_all(f);
  const Neighbourhood ring = build_neighbourhood(f.rest, f.triangles);
  const PlacementLayout layout = placement_layout(ring, f.rest);
  const auto n = static_cast<int>(frames.size());
  std::vector<Eigen::Vector3d> centre;
  for (const Positions& p : frames) centre.push_back(body_centroid(layout, ring, p));
  // A frame starts a clip when a clip starts there (the whole set is one
  // clip without clips).
  std::vector<bool> starts(static_cast<std::size_t>(n), false);
  if (n > 0) starts[0] = true;
  for (const Clip& c : f.clips) {
    if (c.first >= 0 && c.first < n) starts[static_cast<std::size_t>(c.first)] = true;
  }
  std::vector<Eigen::VectorXd> out;
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    if (!starts[i]) {
      v = centre[i] - centre[i - 1];
    } else if (k + 1 < n && !starts[i + 1]) {
      v = centre[i + 1] - centre[i];
    }
    out.push_back(placement_values(layout, ring, frames[i], f.raw(k), v));
  }
  return out;
}

}  // namespace animrt::seqnet
