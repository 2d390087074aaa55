#pragma once
// Checks and clean-up shared by the mesh readers.

#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet::detail {

// Merges vertices whose positions are exactly equal in every frame and that
// share a group (game formats split vertices at texture seams; a group is
// one surface, so separate surfaces stay separate pieces). Triangles are
// renumbered; vertices keep the order of their first occurrence.
void merge_coincident(MeshSequence& sequence, const std::vector<int>& group);

// Game models carry a few edges shared by more than two triangles (fins,
// overlapping parts). Every triangle beyond the second on such an edge gets
// its own copies of its three vertices, so it becomes a piece of its own.
// Returns the number of triangles detached.
int detach_non_manifold(MeshSequence& sequence);

// Throws InputError naming `file` and the frame for: no frames or no
// triangles, frames of different sizes, a vertex index out of range, a
// triangle that repeats a vertex or has zero area, an edge shared by more
// than two triangles, a position that is not finite. Zero area is judged in
// the first frame, and only when that frame is the sequence's own template:
// a posed frame of a known mesh (`pose`) may flatten a triangle.
void validate_mesh(const MeshSequence& sequence, const std::string& file, bool pose = false);

}  // namespace animrt::seqnet::detail
