#pragma once
// Mesh frames in and out of the sequence network, and generation from
// initial frames (paper section 4.3) with a trained mesh model: the initial
// frames' features are fed to the forward chain, which then runs on its own
// output; long sequences chain windows of the model's length, each run
// started from the last frames of the one before. Plain C++ on
// SeqNetInference; no libtorch.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/mesh_sequence.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"

namespace animrt::seqnet {

struct GenerateOptions {
  int frames = 32;  // generated frames, after the initial ones
  // Unset: every run starts from the trained state s0. Set: every state
  // entry of every run is drawn from N(s0, s0^2) with this seed.
  std::optional<std::uint64_t> random_state;
};

// The model's input in its units (dims x frames) for frames of the model's
// mesh: raw deformation features (9 V, vertex-major) against the model's
// template, rotations followed from frame to frame in the given order, then
// for a model with placement nodes their numbers (placement_nodes.hpp), the
// body's velocity taken per `frames_apart` frames between consecutive
// given frames (keys: the gap + 1). Throws InputError naming `model_path`
// when the frames are of another mesh.
FrameMatrix mesh_features(const ModelFile& model, const std::string& model_path,
                          const std::vector<Positions>& frames,
                          const std::vector<std::array<int, 3>>& triangles,
                          double frames_apart = 1.0);

// The initial frames (1 or more, of the model's mesh) followed by the
// generated ones, as vertex positions; the initial frames are returned
// unchanged. With placement nodes the body moves on from the last initial
// frame by the generated velocities and every other piece follows its
// anchor. Without (a model of an older build) each piece of a generated
// frame is moved by the mean offset of that piece of the last initial frame
// from its own reconstruction. Throws InputError naming `model_path` when
// the frames are of another mesh or as many as the model's window.
std::vector<Positions> generate_mesh(const ModelFile& model, const std::string& model_path,
                                     const std::vector<Positions>& initial,
                                     const std::vector<std::array<int, 3>>& triangles,
                                     const GenerateOptions& options);

// A completed mesh sequence (`completion` of these keys with `gap` frames
// between each two): the keys as given, the in-betweens reconstructed. With
// placement nodes the body moves by the completed velocities from key a,
// what it misses at key b spread linearly over the gap, and every other
// piece follows its anchor. Without, each piece is moved by the blend
// (1 - s) o_a + s o_b at s = t / (gap + 1) of the two keys' offsets from
// their own reconstructions.
std::vector<Positions> completed_mesh(const ModelFile& model, const std::vector<Positions>& keys,
                                      const FrameMatrix& keys_features,
                                      const Completion& completion, int gap);

}  // namespace animrt::seqnet
