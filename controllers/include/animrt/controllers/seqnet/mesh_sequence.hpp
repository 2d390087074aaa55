#pragma once
// A mesh animation sequence: frames of vertex positions over one fixed
// triangle connectivity, and the named clips (frame ranges) a file defines.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace animrt::seqnet {

// Vertex positions of one frame, one column per vertex (3 x V), metres or
// the file's own units.
using Positions = Eigen::Matrix3Xd;

struct Clip {
  std::string name;
  int first = 0;  // first frame
  int count = 0;  // frames
  double fps = 0.0;  // 0 when the file does not say
};

struct MeshSequence {
  std::string source;  // file or folder it was read from ("" when generated)
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise vertex indices
  std::vector<Positions> frames;              // all with the same column count
  std::vector<Clip> clips;                    // may be empty

  int vertex_count() const { return frames.empty() ? 0 : static_cast<int>(frames.front().cols()); }
  int frame_count() const { return static_cast<int>(frames.size()); }
};

}  // namespace animrt::seqnet
