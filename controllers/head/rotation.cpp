// Euler angles, rotation matrices and quaternions; rotation recovery by SVD.

#include "animrt/controllers/head/rotation.hpp"

#include <Eigen/SVD>
#include <cmath>

#include "animrt/core/joint.hpp"

namespace animrt::head {

Eigen::Matrix3d euler_to_matrix(const Euler& e) {
  return (Eigen::AngleAxisd(deg_to_rad(e.yaw), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(deg_to_rad(e.pitch), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(deg_to_rad(e.roll), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Euler matrix_to_euler(const Eigen::Matrix3d& r) {
  Euler e;
  e.pitch = rad_to_deg(std::asin(std::clamp(-r(2, 0), -1.0, 1.0)));
  e.yaw = rad_to_deg(std::atan2(r(1, 0), r(0, 0)));
  e.roll = rad_to_deg(std::atan2(r(2, 1), r(2, 2)));
  return e;
}

Eigen::Quaterniond euler_to_quat(const Euler& e) {
  return Eigen::Quaterniond(euler_to_matrix(e)).normalized();
}

Euler quat_to_euler(const Eigen::Quaterniond& q) {
  return matrix_to_euler(q.normalized().toRotationMatrix());
}

Eigen::Matrix3d rotation_from_markers(const Eigen::MatrixX3d& reference,
                                      const Eigen::MatrixX3d& frame) {
  const Eigen::Matrix3d h = reference.transpose() * frame;  // y^T x_i
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (v * u.transpose()).determinant() < 0 ? -1.0 : 1.0;
  return v * d * u.transpose();  // R = V U^T
}

}  // namespace animrt::head
