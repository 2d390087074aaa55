#pragma once
// Clips from per-frame names: "run1".."run6" -> one clip "run".

#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet::detail {

// Consecutive frames whose names agree once trailing digits are removed form
// one clip. Frames without a name form no clip.
std::vector<Clip> clips_from_frame_names(const std::vector<std::string>& names);

}  // namespace animrt::seqnet::detail
