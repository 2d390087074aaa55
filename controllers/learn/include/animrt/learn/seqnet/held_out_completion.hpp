#pragma once
// How a model completes the held-out frames of its training data against
// linear interpolation of the same keys: what tells the user, while it
// trains, whether the model is worth using yet. No libtorch: the model runs
// on the plain inference.

#include <string>
#include <vector>

#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/learn/seqnet/training.hpp"

namespace animrt::seqnet {

struct HeldOutCompletion {
  int gap = 0;   // frames between two keys
  int gaps = 0;  // gaps measured (0: no held-out piece long enough)
  // Mean over the in-between frames of the root mean square difference from
  // the true frame, as a fraction of each dimension's range (as in
  // SeqNetInference::frame_difference).
  double network = -1.0;
  double interpolation = -1.0;
  // The same keys as meshes, completed and placed as `seq complete` does,
  // against linear interpolation of their vertices (PlacedCompletion);
  // -1 when not measured (joint data, or no placement).
  double placed = -1.0;
  double placed_interpolation = -1.0;
};

// Completion of the frames of one piece (absolute vertex positions, in
// order) with keys every gap + 1 frames from its first, as `seq complete`
// completes key meshes: the keys' features and the body's velocity from
// the keys alone, the in-betweens reconstructed and placed. Sums over the
// in-between frames of the mean vertex distance to the true frame as a
// fraction of its bounding-box diagonal, nothing aligned, for the network
// and for linear interpolation of the keys' vertices.
struct PlacedCompletion {
  int frames = 0;
  double network = 0.0;
  double interpolation = 0.0;
};
void add_placed_completion(const ModelFile& model, const std::string& model_path,
                           SeqNetInference& net, const std::vector<Positions>& frames, int gap,
                           const CompletionOptions& options, PlacedCompletion& sums);

// Keys every gap + 1 frames from each held-out segment's first frame, gap
// the largest up to `max_gap` that fits the longest held-out segment; every
// gap completed once (no retries, the plain states), the chains blended or
// handed over (CompletionOptions::blend). With the held-out segments'
// absolute frames (Segment::placed) and a model with placement nodes, the
// same gaps placed (HeldOutCompletion::placed).
HeldOutCompletion measure_held_out_completion(const ModelFile& model, const TrainingSet& set,
                                              int max_gap = 9, bool blend = true);

}  // namespace animrt::seqnet
