// The bodies' signed distance field (see body_field.hpp).

#include "animrt/learn/seq_corpus/body_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace animrt::learn::seq_corpus {
namespace {

// Polynomial smooth minimum: equal to min(a, b) once they differ by more
// than k, rounded below it by at most k/4 where they are close.
double smooth_min(double a, double b, double k) {
  if (k <= 0.0) return std::min(a, b);
  const double h = std::max(k - std::fabs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

// Smallest radius or half size: how thick the geom is.
double thickness(const GeomShape& g) {
  switch (g.type) {
    case mjGEOM_SPHERE:
    case mjGEOM_CAPSULE:
    case mjGEOM_CYLINDER:
      return g.size.x();
    default:
      return g.size.minCoeff();
  }
}

// Half extents of the geom's box in its own frame.
Eigen::Vector3d half_extents(const GeomShape& g) {
  switch (g.type) {
    case mjGEOM_SPHERE:
      return Eigen::Vector3d::Constant(g.size.x());
    case mjGEOM_CAPSULE:
      return {g.size.x(), g.size.x(), g.size.y() + g.size.x()};
    case mjGEOM_CYLINDER:
      return {g.size.x(), g.size.x(), g.size.y()};
    default:
      return g.size;
  }
}

}  // namespace

double geom_distance(const GeomShape& g, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = g.rot.transpose() * (p - g.pos);
  switch (g.type) {
    case mjGEOM_SPHERE:
      return q.norm() - g.size.x();
    case mjGEOM_CAPSULE: {
      const double z = std::clamp(q.z(), -g.size.y(), g.size.y());
      return (q - Eigen::Vector3d(0, 0, z)).norm() - g.size.x();
    }
    case mjGEOM_CYLINDER: {
      const double dr = std::hypot(q.x(), q.y()) - g.size.x();
      const double dz = std::fabs(q.z()) - g.size.y();
      return std::min(std::max(dr, dz), 0.0) + std::hypot(std::max(dr, 0.0), std::max(dz, 0.0));
    }
    case mjGEOM_ELLIPSOID: {
      // A close bound, exact on the axes (the exact distance has no closed form).
      const double k0 = q.cwiseQuotient(g.size).norm();
      const double k1 = q.cwiseQuotient(g.size.cwiseProduct(g.size)).norm();
      if (k1 <= 0.0) return -g.size.minCoeff();
      return k0 * (k0 - 1.0) / k1;
    }
    default: {  // box, and a mesh by its bounding box
      const Eigen::Vector3d e = q.cwiseAbs() - g.size;
      return e.cwiseMax(0.0).norm() + std::min(e.maxCoeff(), 0.0);
    }
  }
}

BodyField::BodyField(const mjModel* m, const mjData* d, double min_thickness, double blend)
    : blend_(blend) {
  for (int g = 0; g < m->ngeom; ++g) {
    const int type = m->geom_type[g];
    const int body = m->geom_bodyid[g];
    if (body == 0 || type == mjGEOM_PLANE || type == mjGEOM_HFIELD) continue;
    GeomShape s;
    s.body = body;
    s.type = type;
    s.pos = Eigen::Vector3d(d->geom_xpos + 3 * g);
    s.rot = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->geom_xmat + 9 * g);
    s.size = Eigen::Vector3d(m->geom_size + 3 * g);
    if (type == mjGEOM_MESH) {
      // Its bounding box (mesh vertices are in the geom's frame).
      const int mesh = m->geom_dataid[g];
      Eigen::AlignedBox3d box;
      for (int v = 0; v < m->mesh_vertnum[mesh]; ++v) {
        const float* x = m->mesh_vert + 3 * (m->mesh_vertadr[mesh] + v);
        box.extend(Eigen::Vector3d(x[0], x[1], x[2]));
      }
      if (box.isEmpty()) continue;
      s.pos += s.rot * box.center();
      s.size = 0.5 * box.sizes();
      s.type = mjGEOM_BOX;
    }
    s.inflate = std::max(0.0, min_thickness - thickness(s));
    if (std::find(bodies_.begin(), bodies_.end(), body) == bodies_.end()) bodies_.push_back(body);
    geoms_.push_back(s);
  }
  if (geoms_.empty()) throw std::invalid_argument("the model has no solid geoms on its bodies");
  std::sort(bodies_.begin(), bodies_.end());
  for (const auto& g : geoms_) {
    geom_body_slot_.push_back(static_cast<int>(
        std::lower_bound(bodies_.begin(), bodies_.end(), g.body) - bodies_.begin()));
  }
}

double BodyField::distance(const Eigen::Vector3d& p) const {
  double out = geom_distance(geoms_[0], p) - geoms_[0].inflate;
  for (std::size_t i = 1; i < geoms_.size(); ++i) {
    out = smooth_min(out, geom_distance(geoms_[i], p) - geoms_[i].inflate, blend_);
  }
  return out;
}

void BodyField::body_distances(const Eigen::Vector3d& p, std::vector<double>& out) const {
  out.assign(bodies_.size(), 1e300);
  for (std::size_t i = 0; i < geoms_.size(); ++i) {
    double& slot = out[static_cast<std::size_t>(geom_body_slot_[i])];
    slot = std::min(slot, geom_distance(geoms_[i], p) - geoms_[i].inflate);
  }
}

Eigen::AlignedBox3d BodyField::bounds() const {
  Eigen::AlignedBox3d box;
  for (const auto& g : geoms_) {
    const Eigen::Vector3d e = half_extents(g) + Eigen::Vector3d::Constant(g.inflate);
    // The world box of the rotated local box: |R| e.
    const Eigen::Vector3d r = g.rot.cwiseAbs() * e;
    box.extend(g.pos - r);
    box.extend(g.pos + r);
  }
  return box;
}

}  // namespace animrt::learn::seq_corpus
