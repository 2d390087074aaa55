#pragma once
// Clips from per-frame names: "run1".."run6" -> one clip "run".

#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet::detail {

// Consecutive frames whose names agree once trailing digits are removed, and
// whose numbers follow on by one, form one clip. A name split by a jump in
// the numbers gives several clips: death101..106, death201..206 -> death1,
// death2 (Quake II's numbering); run1, run2, run1 -> run_1, run_2. Frames
// without a name form no clip.
std::vector<Clip> clips_from_frame_names(const std::vector<std::string>& names);

}  // namespace animrt::seqnet::detail
