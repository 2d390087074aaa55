#pragma once
// A MuJoCo model's bodies, posed as in one mjData, as a signed distance
// field (negative inside): every solid geom (sphere, capsule, ellipsoid,
// cylinder, box; a mesh by its bounding box) of every body but the world,
// joined by a smooth minimum so that segments grow together at their joints
// instead of meeting in creases.
//
// Geoms thinner than `min_thickness` are inflated to it: a grid can only
// sample a limb at least about one grid step thick, and a coarse skin must
// still have every leg.

#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace animrt::learn::seq_corpus {

struct GeomShape {
  int body = -1;
  int type = 0;  // mjtGeom
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();  // geom frame in world
  Eigen::Vector3d size = Eigen::Vector3d::Zero();     // radii / half sizes
  double inflate = 0.0;                               // added to the surface
};

class BodyField {
 public:
  // `blend`: width of the smooth minimum (0: a plain union).
  BodyField(const mjModel* m, const mjData* d, double min_thickness, double blend);

  // The smooth union of all geoms at `p`.
  double distance(const Eigen::Vector3d& p) const;
  // Bodies that have geoms, in body order.
  const std::vector<int>& bodies() const { return bodies_; }
  // Distance from `p` to each of bodies() (the plain minimum over its geoms),
  // written into `out` (resized to bodies().size()).
  void body_distances(const Eigen::Vector3d& p, std::vector<double>& out) const;
  // Box holding every geom (inflated), world frame.
  Eigen::AlignedBox3d bounds() const;
  const std::vector<GeomShape>& geoms() const { return geoms_; }

 private:
  std::vector<GeomShape> geoms_;
  std::vector<int> bodies_;
  std::vector<int> geom_body_slot_;  // geoms_ index -> bodies_ index
  double blend_;
};

// Signed distance to one geom (without its inflation).
double geom_distance(const GeomShape& g, const Eigen::Vector3d& p);

}  // namespace animrt::learn::seq_corpus
