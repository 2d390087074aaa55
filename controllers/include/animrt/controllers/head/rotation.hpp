#pragma once
// Head rotation conventions.
//
// Frame: x forward (out of the face), y to the head's left, z up.
// Euler angles in degrees, applied as R = Rz(yaw) * Ry(pitch) * Rx(roll):
//   yaw   about z, positive turns the face to its left;
//   pitch about y, positive tips the nose down (a nod);
//   roll  about x, positive tilts the head towards its right shoulder.
// Valid for |pitch| < 90 deg (heads never get near the singularity).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace animrt::head {

struct Euler {
  double yaw = 0.0, pitch = 0.0, roll = 0.0;  // degrees
};

Eigen::Matrix3d euler_to_matrix(const Euler& e);
Euler matrix_to_euler(const Eigen::Matrix3d& r);
Eigen::Quaterniond euler_to_quat(const Euler& e);
Euler quat_to_euler(const Eigen::Quaterniond& q);

// The paper's Eq. 1-2: with `reference` and `frame` both N x 3 marker
// positions (same marker order, each already translated to its own origin),
// SVD of reference^T * frame = U D V^T gives R = V U^T, the rotation that
// carries the reference pose onto the frame (frame_n ~= R * reference_n).
// A reflection (det R = -1, from noisy or nearly planar markers) is turned
// into the nearest proper rotation.
Eigen::Matrix3d rotation_from_markers(const Eigen::MatrixX3d& reference,
                                      const Eigen::MatrixX3d& frame);

}  // namespace animrt::head
