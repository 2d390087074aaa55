#pragma once
// Sequence generation from initial frames (paper section 4.3) with a trained
// mesh model: the initial frames' features are fed to the forward chain,
// which then runs on its own output; long sequences chain windows of the
// model's length, each run started from the last frames of the one before.
// The API needs no libtorch; the implementation is in animrt_seqnet_torch.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"

namespace animrt::seqnet {

struct GenerateOptions {
  int frames = 32;  // generated frames, after the initial ones
  // Unset: every run starts from the trained state s0. Set: every state
  // entry of every run is drawn from N(s0, s0^2) with this seed.
  std::optional<std::uint64_t> random_state;
  int threads = 1;
};

// The initial frames (1 or more, of the model's mesh) followed by the
// generated ones, as vertex positions (each connected piece placed by its
// lowest vertex, as reconstruction does). Throws InputError naming
// `model_path` when the frames are of another mesh.
std::vector<Positions> generate_mesh(const ModelFile& model, const std::string& model_path,
                                     const std::vector<Positions>& initial,
                                     const std::vector<std::array<int, 3>>& triangles,
                                     const GenerateOptions& options);

}  // namespace animrt::seqnet
