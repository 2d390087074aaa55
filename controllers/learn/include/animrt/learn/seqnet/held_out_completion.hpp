#pragma once
// How a model completes the held-out frames of its training data against
// linear interpolation of the same keys: what tells the user, while it
// trains, whether the model is worth using yet. No libtorch: the model runs
// on the plain inference.

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
};

// Keys every gap + 1 frames from each held-out segment's first frame, gap
// the largest up to `max_gap` that fits the longest held-out segment; every
// gap completed once (no retries, the plain states), the chains blended or
// handed over (CompletionOptions::blend).
HeldOutCompletion measure_held_out_completion(const ModelFile& model, const TrainingSet& set,
                                              int max_gap = 9, bool blend = true);

}  // namespace animrt::seqnet
