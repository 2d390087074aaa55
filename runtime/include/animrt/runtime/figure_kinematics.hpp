#pragma once
// The figure's shape for readers of the run (the dashboard draws it): its
// bodies with their geoms, and where every body is for given joint
// positions. The runtime does not know how a model is loaded; sim/mujoco
// implements this over an MJCF model, and the CLI wires it in.

#include <array>
#include <span>
#include <string>
#include <vector>

namespace animrt {

// A geom in its body's frame, with MuJoCo's conventions: "box" size is the
// half-sizes, "sphere" [r], "capsule" and "cylinder" [r, half-length] along
// the geom's z axis, "ellipsoid" the radii; other types (mesh, plane) are
// named but have no size the reader can draw.
struct FigureGeom {
  std::string type;
  std::vector<double> size;
  std::array<double, 3> pos{};
  std::array<double, 4> quat{1, 0, 0, 0};  // w, x, y, z
  std::array<float, 4> rgba{0.5f, 0.5f, 0.5f, 1.0f};
};

struct FigureBody {
  std::string name;
  int parent = -1;  // index into bodies(), -1 for a body on the world
  std::vector<FigureGeom> geoms;
};

// A body's pose in the world frame.
struct BodyPose {
  std::array<double, 3> pos{};
  std::array<double, 4> quat{1, 0, 0, 0};  // w, x, y, z
};

class FigureKinematics {
 public:
  virtual ~FigureKinematics() = default;
  virtual const std::vector<FigureBody>& bodies() const = 0;
  // Body poses (indexed like bodies()) for robot joint positions (indexed
  // like the robot's joints; joints the model does not have are ignored).
  // Not for the real-time cycle: one reader thread at a time.
  virtual void pose(std::span<const double> joint_positions, std::span<BodyPose> out) = 0;
};

}  // namespace animrt
