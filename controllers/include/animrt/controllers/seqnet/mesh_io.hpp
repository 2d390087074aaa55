#pragma once
// Reading and writing mesh sequences. Every reader throws InputError naming
// the file (and the frame, where the problem is in one) for a file it
// cannot use: truncated, wrong magic, frame counts that disagree,
// connectivity that differs between frames. Files may be gzip-compressed.

#include <string>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet {

// A folder of OBJ files, one frame each, in name order; all must share one
// connectivity.
MeshSequence read_obj_sequence(const std::string& folder);
// One OBJ file as a one-frame sequence.
MeshSequence read_obj(const std::string& file);
// Quake II MD2 / Quake III MD3: every frame, vertices split at texture
// seams merged by position, clips by frame range where the file or its
// animation.cfg names them.
MeshSequence read_md2(const std::string& file);
MeshSequence read_md3(const std::string& file);
// By extension (.obj, .md2, .md3, each optionally .gz) or a folder of OBJs.
MeshSequence read_mesh_sequence(const std::string& path);
// One posed frame of a model's mesh (a key or an initial frame): as
// read_mesh_sequence, but an OBJ's triangles may have zero area, since the
// frame is measured against the model's template, not against itself (a
// game pose can flatten a triangle: frame 28 of Irrlicht's sydney.md2).
MeshSequence read_mesh_pose(const std::string& path);

// One OBJ per frame: DIR/frame_0000.obj, ... (the folder is created).
void write_obj_sequence(const std::string& folder, const MeshSequence& sequence);
void write_obj(const std::string& file, const MeshSequence& sequence, int frame);

}  // namespace animrt::seqnet
