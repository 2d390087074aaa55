#pragma once
// Training the sequence network (docs/seqnet.md, "Training"): the data (a
// mesh feature file, or joint-angle CSVs), the held-out split, the batch
// sampling, checkpoints and the loss plot. The API needs no libtorch; the
// implementation is in animrt_seqnet_torch.

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"

namespace animrt::seqnet {

// Frames of one clip piece, all training or all held out; `values` is
// count x D, row-major, normalised to [-0.95, 0.95].
struct Segment {
  int dataset = 0;
  bool held_out = false;
  int first = 0;  // its first frame in its data file
  int count = 0;
  std::vector<float> values;
  // A held-out segment of a feature file with its placement: its frames'
  // vertices in absolute coordinates (what the placed completion is
  // measured against).
  std::vector<Positions> placed;
};

struct TrainingSet {
  ModelKind kind = ModelKind::mesh;
  int dims = 0;
  // Mesh data: the template and connectivity. Joint data: the joints.
  ModelFile description;  // shape.kind, vertex/joint count, rest, triangles, joint_names, low, high
  std::vector<std::string> sources;
  std::vector<Segment> segments;
};

// DATA: one mesh feature file (animrt seq features), or one or more joint
// CSVs with the same joints. Each file is a dataset: one contiguous block
// of `held_out` of its frames, placed by the seed, is held out. Throws
// InputError for bad files (naming file, line, column).
// With `held_out_clips` (clip names of a feature file, or joint CSV paths)
// those clips are held out whole instead of the block, e.g. the walks of
// another seed; a name that is no clip of the data throws InputError.
TrainingSet load_training_set(const std::vector<std::string>& files, std::uint64_t seed,
                              double held_out = 0.2,
                              const std::vector<std::string>& held_out_clips = {});

struct TrainOptions {
  std::vector<std::string> data;
  std::string out;        // the model; OUT.ckpt is the checkpoint, OUT.svg the loss plot
  std::string resume;     // a checkpoint to continue from
  int iterations = 1000;  // total, counting those before a resume
  std::uint64_t seed = 1;
  int threads = 1;
  int batch = 8;
  int window = 32;
  int stride = 1;
  double learning_rate = 1e-3;
  int checkpoint_every = 100;
  int report_every = 10;
  // Held-out completion against linear interpolation, printed every so many
  // iterations (0: only at the end) and at the end, where the model file
  // keeps it.
  int held_out_every = 100;
  double held_out = 0.2;
  std::vector<std::string> held_out_clips;  // held out whole instead (load_training_set)
  // The decoder's last layer starts at zero (SeqNetImpl::zero_output_layer).
  bool zero_output = true;
  // The held-out completion blends the chains (CompletionOptions::blend).
  bool blend = true;
  // Network size (paper values by default).
  int latent = 128;
  int hidden = 128;
  int lstm_layers = 3;
  int channels = 9;
  int dense_width = 64;
  // Ablations: the KL and L2 terms' weights (1: the paper) and bidirectional
  // training.
  double kl_weight = 1.0;
  double l2_weight = 1.0;
  bool bidirectional = true;
  // Weight of the placement nodes' numbers (where the body goes, where the
  // other pieces sit) in the frame distances of the training loss, against
  // 1 for every deformation feature; > 0. Other than 1 needs mesh data with
  // placement. The held-out lines are measured unweighted.
  double placement_weight = 1.0;
  // All gradients together scaled down to this L2 norm when longer (0: no
  // clipping; train_step).
  double clip_gradient = 0.0;
};

struct LossRecord {
  double recon = 0, bidir = 0, kl = 0, l2 = 0, total = 0;
};

struct TrainResult {
  int iterations = 0;    // total trained
  int run = 0;           // trained in this call
  LossRecord last;       // last iteration's batch
  double held_out = -1;  // held-out reconstruction loss (-1: no held-out window)
  // Held-out completion and linear interpolation at the end (-1: not measured).
  double held_out_completion = -1;
  double held_out_interpolation = -1;
  // The measurement kept in OUT.best: the best held-out completion of the
  // run (placed vertices where measured, else features) and its iteration
  // (0: none written).
  int best_iteration = 0;
  // On a resume: the iteration of the OUT.best found there when it was
  // measured first and no measurement of this run beat it (-1: none).
  int kept_best_iteration = -1;
  // Iterations whose gradient norm was above clip_gradient, and the
  // largest norm of the run (0 without clipping).
  int clipped = 0;
  double largest_gradient_norm = 0;
  double seconds = 0;
};

// Trains, printing a progress line every report_every iterations to
// `progress`; writes the model, checkpoint and plot. Throws InputError for
// bad data or a checkpoint that does not fit the data.
TrainResult train(const TrainOptions& options, std::ostream& progress);

// The loss history as an SVG line plot (log scale), one line per term.
std::string loss_plot_svg(const std::vector<LossRecord>& history);

}  // namespace animrt::seqnet
