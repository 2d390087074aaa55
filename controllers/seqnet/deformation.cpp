#include "animrt/controllers/seqnet/deformation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <queue>

namespace animrt::seqnet {

EdgeWeights cotangent_weights(const Positions& rest, const Triangles& triangles) {
  std::map<std::array<int, 2>, double> sum;
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
      const Eigen::Vector3d u = rest.col(a) - rest.col(c);
      const Eigen::Vector3d v = rest.col(b) - rest.col(c);
      const double cross = u.cross(v).norm();
      const double cot = cross > 0.0 ? u.dot(v) / cross : 0.0;
      sum[{std::min(a, b), std::max(a, b)}] += 0.5 * cot;
    }
  }
  EdgeWeights out;
  for (const auto& [edge, w] : sum) {
    out.edges.push_back(edge);
    out.weights.push_back(std::max(0.0, w));
  }
  return out;
}

Positions vertex_normals(const Positions& points, const Triangles& triangles) {
  Positions n = Positions::Zero(3, points.cols());
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = points.col(t[0]);
    const Eigen::Vector3d face = (points.col(t[1]) - a).cross(points.col(t[2]) - a);  // 2 x area
    for (int c : t) n.col(c) += face;
  }
  for (Eigen::Index i = 0; i < n.cols(); ++i) {
    const double len = n.col(i).norm();
    if (len > 0.0) n.col(i) /= len;
  }
  return n;
}

std::vector<double> ring_areas(const Positions& points, const Triangles& triangles) {
  std::vector<double> area(static_cast<std::size_t>(points.cols()), 0.0);
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = points.col(t[0]);
    const double face = 0.5 * (points.col(t[1]) - a).cross(points.col(t[2]) - a).norm();
    for (int c : t) area[c] += face;
  }
  return area;
}

Neighbourhood build_neighbourhood(const Positions& rest, const Triangles& triangles) {
  const EdgeWeights cot = cotangent_weights(rest, triangles);
  Neighbourhood out;
  const int v = static_cast<int>(rest.cols());
  out.vertex_count = v;
  double mean = 0.0;
  for (double w : cot.weights) mean += w;
  mean = cot.weights.empty() ? 1.0 : mean / static_cast<double>(cot.weights.size());
  const double floor = 1e-3 * (mean > 0.0 ? mean : 1.0);
  std::vector<int> degree(static_cast<std::size_t>(v), 0);
  for (const auto& e : cot.edges) {
    ++degree[e[0]];
    ++degree[e[1]];
  }
  out.offsets.assign(static_cast<std::size_t>(v) + 1, 0);
  for (int i = 0; i < v; ++i) out.offsets[i + 1] = out.offsets[i] + degree[i];
  out.neighbours.resize(static_cast<std::size_t>(out.offsets[v]));
  out.weights.resize(out.neighbours.size());
  std::vector<int> fill(out.offsets.begin(), out.offsets.end() - 1);
  for (std::size_t e = 0; e < cot.edges.size(); ++e) {
    const double w = std::max(cot.weights[e], floor);
    for (int side = 0; side < 2; ++side) {
      const int i = cot.edges[e][side];
      out.neighbours[fill[i]] = cot.edges[e][1 - side];
      out.weights[fill[i]++] = w;
    }
  }
  out.piece.assign(static_cast<std::size_t>(v), -1);
  for (int s = 0; s < v; ++s) {
    if (out.piece[s] >= 0) continue;
    std::queue<int> open;
    open.push(s);
    out.piece[s] = out.piece_count;
    while (!open.empty()) {
      const int i = open.front();
      open.pop();
      for (int k = out.offsets[i]; k < out.offsets[i + 1]; ++k) {
        const int j = out.neighbours[k];
        if (out.piece[j] < 0) {
          out.piece[j] = out.piece_count;
          open.push(j);
        }
      }
    }
    ++out.piece_count;
  }
  out.ring_area = ring_areas(rest, triangles);
  return out;
}

std::vector<Eigen::Matrix3d> deformation_gradients(const Neighbourhood& ring,
                                                   const Triangles& triangles,
                                                   const Positions& rest, const Positions& frame) {
  // Flat rings: below this ratio of the smallest to the largest eigenvalue
  // of the template's weighted scatter, the normal direction is added.
  constexpr double kFlatRatio = 1e-2;
  const Positions rest_normals = vertex_normals(rest, triangles);
  const Positions frame_normals = vertex_normals(frame, triangles);
  const std::vector<double> frame_area = ring_areas(frame, triangles);
  std::vector<Eigen::Matrix3d> out(static_cast<std::size_t>(ring.vertex_count));
  for (int i = 0; i < ring.vertex_count; ++i) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d b = Eigen::Matrix3d::Zero();
    for (int k = ring.offsets[i]; k < ring.offsets[i + 1]; ++k) {
      const int j = ring.neighbours[k];
      const double w = ring.weights[k];
      const Eigen::Vector3d d = rest.col(i) - rest.col(j);
      const Eigen::Vector3d e = frame.col(i) - frame.col(j);
      a.noalias() += w * d * d.transpose();
      b.noalias() += w * e * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
    const double largest = std::max(eig.eigenvalues()[2], 0.0);
    const double smallest = std::max(eig.eigenvalues()[0], 0.0);
    const double mu = kFlatRatio * largest - smallest;
    if (mu > 0.0 || largest <= 0.0) {
      const double extra = largest > 0.0 ? mu : 1.0;
      const Eigen::Vector3d n = rest_normals.col(i);
      // Template normal goes to the frame normal, scaled like the ring's
      // edges (square root of the area change).
      const double scale =
          ring.ring_area[i] > 0.0 ? std::sqrt(frame_area[i] / ring.ring_area[i]) : 1.0;
      const Eigen::Vector3d m = frame_normals.col(i) * scale;
      a.noalias() += extra * n * n.transpose();
      b.noalias() += extra * m * n.transpose();
      if (n.squaredNorm() == 0.0) {  // nothing defines the normal: identity there
        a += extra * Eigen::Matrix3d::Identity();
        b += extra * Eigen::Matrix3d::Identity();
      }
    }
    out[i] = b * a.inverse();
  }
  return out;
}

Polar polar_decomposition(const Eigen::Matrix3d& t) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(t, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d v = svd.matrixV();
  Eigen::Vector3d sigma = svd.singularValues();
  if ((u * v.transpose()).determinant() < 0.0) {
    // A reflection: flip the direction of the smallest singular value, so R
    // stays a rotation and S takes the negative stretch.
    u.col(2) = -u.col(2);
    sigma[2] = -sigma[2];
  }
  Polar out;
  out.rotation = u * v.transpose();
  out.stretch = v * sigma.asDiagonal() * v.transpose();
  out.stretch = 0.5 * (out.stretch + out.stretch.transpose()).eval();
  return out;
}

Eigen::Vector3d rotation_log(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

Eigen::Vector3d closest_equivalent(const Eigen::Vector3d& v, const Eigen::Vector3d& reference) {
  const double theta = v.norm();
  if (theta < 1e-6) {
    // (Nearly) the identity, whose axis is noise: 2 pi k about the
    // reference's axis is the closest.
    const double len = reference.norm();
    if (len < 1e-12) return v;
    const double k = std::round(len / (2.0 * std::numbers::pi));
    return v + reference / len * (2.0 * std::numbers::pi * k);
  }
  const Eigen::Vector3d axis = v / theta;
  // |phi axis - ref|^2 is smallest for phi nearest axis . ref.
  const double s = axis.dot(reference);
  const double k = std::round((s - theta) / (2.0 * std::numbers::pi));
  return axis * (theta + 2.0 * std::numbers::pi * k);
}

}  // namespace animrt::seqnet
