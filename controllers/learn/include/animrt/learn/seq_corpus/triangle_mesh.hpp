#pragma once
// An indexed triangle mesh, and the checks a skin must pass: one connected
// component, closed and manifold (every edge in exactly two triangles, used
// once in each direction), no degenerate triangles.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <functional>
#include <vector>

namespace animrt::learn::seq_corpus {

struct TriangleMesh {
  Eigen::Matrix3Xd vertices;                  // one column per vertex
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

// The zero level set of `field` (negative inside) by marching tetrahedra on
// a grid of spacing `step` over `box`, which must hold the whole surface
// with the field positive on its faces. Each cube splits into six
// tetrahedra around its main diagonal, so neighbouring cubes agree on their
// shared faces and the surface is closed; vertices sit on grid edges, one
// per edge, and are shared by the triangles that meet there. A crossing is
// kept at least a tenth of an edge from either end, so no triangle is
// degenerate.
TriangleMesh marching_tetrahedra(const std::function<double(const Eigen::Vector3d&)>& field,
                                 const Eigen::AlignedBox3d& box, double step);

// The connected component with the most triangles, its vertices renumbered
// in order of first use.
TriangleMesh largest_component(const TriangleMesh& mesh);

// A closed manifold mesh with `target_vertices` vertices (fewer collapses
// when no more are allowed) by quadric error edge collapses: each collapse
// moves the two ends of an edge to the point closest to their triangles'
// planes. An edge collapses only when its ends share exactly the two
// vertices across it (so the mesh stays manifold, its genus unchanged) and
// no triangle around it flips or becomes a sliver.
TriangleMesh decimate(const TriangleMesh& mesh, int target_vertices);

struct MeshReport {
  int vertices = 0;
  int triangles = 0;
  int edges = 0;
  int components = 0;            // connected through shared edges
  int boundary_edges = 0;        // in one triangle
  int nonmanifold_edges = 0;     // in three or more
  int misoriented_edges = 0;     // used twice in the same direction
  int nonmanifold_vertices = 0;  // triangles around it not one fan
  int degenerate = 0;            // repeated vertex, or area below the threshold
  int unused_vertices = 0;
  double min_area = 0.0;
  double min_angle_deg = 0.0;
  int euler() const { return vertices - edges + triangles; }
  bool closed_manifold() const {
    return boundary_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0 &&
           nonmanifold_vertices == 0 && unused_vertices == 0;
  }
};

// `min_area`: triangles smaller than this count as degenerate.
MeshReport check_mesh(const TriangleMesh& mesh, double min_area);

// Enclosed volume (positive when triangles face outward).
double enclosed_volume(const TriangleMesh& mesh);

}  // namespace animrt::learn::seq_corpus
