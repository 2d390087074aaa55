#pragma once
// Head-pose tracks and their file formats.
//
// Euler CSV: a header row naming at least the columns time_s, yaw_deg,
//   pitch_deg, roll_deg (any order, extra columns ignored), then one row per
//   frame with increasing time. Angles as in rotation.hpp.
// BVH: the rotation of the head joint relative to the torso joint (product of
//   the local rotations on the chain below the torso down to the head), each
//   joint's rotation channels applied in the order the file lists them. BVH
//   axes (x left, y up, z forward) are mapped to ours (x forward, y left,
//   z up).
// Marker CSV: a header row time_s, then NAME_x, NAME_y, NAME_z per marker
//   (metres or any unit, in our axes), one row per frame. Each frame is
//   translated to its "nose" marker when there is one, else to its centroid;
//   the rotation against the reference frame (frame 0) is recovered by SVD
//   (rotation_from_markers).

#include <string>
#include <vector>

#include "animrt/controllers/head/rotation.hpp"

namespace animrt::head {

struct PoseTrack {
  std::vector<double> times;  // seconds, increasing
  std::vector<Euler> poses;
  std::size_t size() const { return times.size(); }
  // Linear interpolation per angle; holds the end poses outside the track.
  Euler at(double t) const;
};

PoseTrack load_euler_csv(const std::string& path);
void write_euler_csv(const std::string& path, const PoseTrack& track);

struct BvhOptions {
  std::string head_joint = "Head";
  std::string torso_joint;  // empty: the root joint
};
PoseTrack load_bvh(const std::string& path, const BvhOptions& options = {});

PoseTrack load_marker_csv(const std::string& path, int reference_frame = 0);

// By extension: *.bvh, *.markers.csv, else Euler CSV.
PoseTrack load_pose_file(const std::string& path);

}  // namespace animrt::head
