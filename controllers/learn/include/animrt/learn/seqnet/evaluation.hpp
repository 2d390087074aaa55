#pragma once
// Evaluation of a trained mesh model on the held-out frames of its training
// feature file (paper sections 4.2-4.4): errors of generated frames against
// linear extrapolation in feature space (Table 1), of completed gaps against
// linear interpolation in feature and vertex space, and the change between
// consecutive generated frames (Fig. 2). docs/seqnet.md, "Evaluation".

#include <string>
#include <vector>

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/mesh_sequence.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"

namespace animrt::seqnet {

struct EvaluationOptions {
  double held_out = 0.2;  // the trainer's fraction (its seed is the model's)
  // Clips of the feature file held out whole instead of the fraction (the
  // trainer's --held-out-clip); a name that is no clip is an InputError
  // naming `data_path`.
  std::vector<std::string> held_out_clips;
  std::string data_path;
  std::vector<int> initial_frames{1, 3};
  std::vector<int> horizons{5, 10, 15};  // generated frames measured
  int gap = 9;                           // completion: frames between keys
  CompletionOptions completion;
  int change_frames = 32;  // frames generated for the change per frame
};

// Mean per-vertex distance to the true frame after removing the mean offset
// of each connected piece (generated frames carry no translation), in the
// data's units, averaged over `frames` frames.
struct GenerationRow {
  int initial = 0;  // initial frames given
  int horizon = 0;  // n-th generated frame
  int frames = 0;   // starts measured
  double learned = 0;
  double extrapolated =
      0;  // linear in feature space from the last two given frames (u = 1: repeated)
};

struct CompletionRow {
  int gaps = 0;
  int merged = 0;  // merged below the threshold
  int frames = 0;  // in-between frames measured
  double learned = 0;
  double feature_linear = 0;
  double vertex_linear = 0;
  // The same keys completed as `seq complete` completes key meshes (their
  // features and body velocity taken from the keys alone) and placed, with
  // nothing aligned: mean over the in-between frames of the mean vertex
  // distance to the true frame as a fraction of its bounding-box diagonal,
  // and the same for linear interpolation of the keys' vertices. Measured
  // (placed_frames > 0) when the model has placement nodes and the feature
  // file its placement.
  int placed_frames = 0;
  double placed = 0;
  double placed_vertex_linear = 0;
};

struct Evaluation {
  std::vector<Clip> pieces;  // held-out frames of the data, cut at its clips
  double diagonal = 0;       // mean bounding-box diagonal of the held-out frames
  std::vector<GenerationRow> generation;
  CompletionRow completion;
  // Per step t (0-based, t -> t + 1): mean over starts of |x(t+1) - x(t)| / |x(t)|
  // on the normalised features, generated from one initial frame, and the
  // same over the held-out frames themselves (one value).
  std::vector<double> change_generated;
  double change_truth = 0;
  int change_starts = 0;
};

// `data` must be the model's training feature file (same template and
// connectivity): InputError naming `model_path` otherwise. Pieces too short
// for a measurement are skipped; none at all is an InputError.
Evaluation evaluate(const ModelFile& model, const std::string& model_path,
                    const SequenceFeatures& data, const EvaluationOptions& options = {});

}  // namespace animrt::seqnet
