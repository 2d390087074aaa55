#pragma once
// The sequence network's numbers must stay finite: a model whose weights
// overflow (a valid file with weights of 3e38) would otherwise write inf and
// NaN frames that a figure or a mesh viewer then meets.

#include <string>
#include <vector>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"

namespace animrt::seqnet {

// Frames generated from its own training range (each dimension at low, the
// middle and high) by a short chain in both directions must be finite;
// throws InputError naming `file` otherwise.
void check_model_output(const ModelFile& model, const std::string& file);

// read_model_file followed by check_model_output.
ModelFile read_checked_model(const std::string& file);

// Throws InputError naming the model `file`, the frame (0-based column) and
// the dimension (by name when `names` has one per row) of the first
// non-finite number, so that nothing non-finite is ever written.
void require_finite_frames(const FrameMatrix& frames, const std::string& file,
                           const std::vector<std::string>& names = {});

}  // namespace animrt::seqnet
