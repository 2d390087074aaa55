#pragma once
// The held-out part of a training data set (paper section 4.1: a contiguous
// subsequence of 20 % of each dataset), shared by the trainer, which leaves
// it out, and the evaluation, which measures on it.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet {

// The held-out block of dataset number `dataset` (its position among the
// training files) of n frames: [first, first + count), count =
// round(fraction * n), placed by the seed.
std::pair<int, int> held_out_block(int n, double fraction, std::uint64_t seed, int dataset);

// The held-out frames of one data set cut at its clips (a clip is one
// motion): the pieces of every clip that lie in the block, in frame order.
// Without clips the whole set is one clip. `name` is the clip's.
std::vector<Clip> held_out_pieces(int n, const std::vector<Clip>& clips, double fraction,
                                  std::uint64_t seed, int dataset);

// Throws InputError naming `file` and --held-out-clip, listing the clips
// `have`, for a name in `wanted` that is none of them.
void check_clip_names(const std::vector<std::string>& wanted, const std::vector<std::string>& have,
                      const std::string& file);

// The clips named in `names` (--held-out-clip), held out whole, in frame
// order; an unknown name is refused as by check_clip_names. A file of
// `frames` frames without clips is one clip, "all", as the trainer reads it.
std::vector<Clip> named_clips(const std::vector<Clip>& clips, int frames,
                              const std::vector<std::string>& names, const std::string& file);

// An error against a reference's, as the held-out lines print it: "46 %
// better" (smaller) or "3 % worse" (not smaller).
std::string compared_with(double error, double reference);

}  // namespace animrt::seqnet
