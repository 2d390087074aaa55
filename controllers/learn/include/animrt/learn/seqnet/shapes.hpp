#pragma once
// Generated meshes for tests and benchmarks.

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet {

// A closed cylinder along z from 0 to length: `rings` rings of `around`
// vertices (radius 1) and one centre vertex per cap; rings * around + 2
// vertices.
MeshSequence make_bar(int rings, int around, double length);

// A sequence of `frames` frames twisting the bar about z: in frame f the
// ring at height z turns by total_angle * f / (frames - 1) * ramp(z / length),
// where ramp is 0 up to 0.25, 1 from 0.75 and smooth between, so the top
// quarter turns rigidly and the middle half takes the twist.
MeshSequence make_twisting_bar(int rings, int around, double length, double total_angle,
                               int frames);

// An icosahedron subdivided `levels` times onto the unit sphere.
MeshSequence make_icosphere(int levels);

}  // namespace animrt::seqnet
