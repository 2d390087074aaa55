// The command of the sequence network that needs libtorch: `train`. It lives
// in its own executable, animrt-seqnet, so that the runtime binary (animrt)
// neither loads libtorch (half a second and 130 MB at every start) nor needs
// it on a robot's controller; `animrt seq train` hands over to it
// (runtime/cli/seq_net_forward.cpp). Generation and completion run in
// animrt itself on the plain C++ inference.

#include "seq_net_commands.hpp"

#include <array>
#include <cstdint>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../option_checks.hpp"
#include "../subcommand.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/training.hpp"

namespace animrt::cli {
namespace {

int run_train(const seqnet::TrainOptions& o) {
  const seqnet::TrainResult r = seqnet::train(o, std::cout);
  std::cout << "trained " << r.run << " iterations (" << r.iterations << " in all) in " << r.seconds
            << " s\n";
  return 0;
}

}  // namespace

void add_seq_net_commands(CLI::App& app) {
  CLI::App* seq = &app;
  auto train_args = std::make_shared<seqnet::TrainOptions>();
  auto* train = seq->add_subcommand(
      "train", "Train the bidirectional sequence network on mesh features or joint CSVs");
  train
      ->add_option("DATA", train_args->data,
                   "one feature file (animrt seq features), or joint-angle CSVs")
      ->required();
  train->add_option("--out", train_args->out, "model file (also OUT.ckpt and OUT.svg)")
      ->required()
      ->check(kOutputFile);
  train->add_option("--iterations", train_args->iterations, "total iterations")
      ->check(CLI::Range(1, 100000000));
  train->add_option("--seed", train_args->seed, "seed for the split, the batches and the weights")
      ->check(kSeed);
  train->add_option("--threads", train_args->threads, "libtorch threads")
      ->check(CLI::Range(1, 256));
  train->add_option("--resume", train_args->resume, "continue from this checkpoint");
  train->add_option("--batch", train_args->batch, "sequences per iteration (paper: 8)")
      ->check(CLI::Range(1, 1024));
  train->add_option("--window", train_args->window, "frames per sequence (paper: 32)")
      ->check(CLI::Range(2, 4096));
  train->add_option("--stride", train_args->stride, "2: every other frame, for slow motion")
      ->check(CLI::Range(1, 16));
  train->add_option("--learning-rate", train_args->learning_rate, "Adam step size")
      ->check(kPositiveNumber);
  train->add_option("--checkpoint-every", train_args->checkpoint_every, "iterations")
      ->check(CLI::Range(1, 100000000));
  train->add_option("--report-every", train_args->report_every, "iterations per progress line")
      ->check(CLI::Range(1, 100000000));
  train
      ->add_option("--held-out-every", train_args->held_out_every,
                   "iterations between held-out completion lines (0: only at the end)")
      ->check(kNonNegativeNumber);
  train->add_option("--held-out-clip", train_args->held_out_clips,
                    "hold out this clip whole (feature file clip, or joint CSV) instead of a "
                    "block of every file; repeatable");
  train->add_option("--zero-output", train_args->zero_output,
                    "start the decoder's last layer at zero (false: random, as the paper)");
  train->add_flag("!--hand-over", train_args->blend,
                  "held-out completion hands over between the chains (the paper) instead of "
                  "blending them");
  train->add_option("--latent", train_args->latent, "latent size")->check(CLI::Range(1, 4096));
  train->add_option("--hidden", train_args->hidden, "LSTM hidden units")
      ->check(CLI::Range(1, 4096));
  train->add_option("--lstm-layers", train_args->lstm_layers, "LSTM layers")
      ->check(CLI::Range(1, 8));
  train->add_option("--dense-width", train_args->dense_width, "joint models: hidden layer width")
      ->check(CLI::Range(1, 4096));
  train->add_option("--kl-weight", train_args->kl_weight, "0 turns L_KL off (ablation)")
      ->check(FiniteRange(0.0, 100.0));
  train->add_option("--l2-weight", train_args->l2_weight, "0 turns the L2 term off (ablation)")
      ->check(FiniteRange(0.0, 100.0));
  train
      ->add_option("--placement-weight", train_args->placement_weight,
                   "weight of the placement numbers (where the body goes) in the loss, "
                   "against 1 for each deformation feature")
      ->check(FiniteRange(1e-3, 1e4));
  train
      ->add_option("--clip-gradient", train_args->clip_gradient,
                   "scale all gradients together down to this L2 norm when longer (0: never)")
      ->check(FiniteRange(0.0, 1e9));
  train->add_flag("!--unidirectional", train_args->bidirectional,
                  "forward chain only, no L_bidir (ablation)");
  set_subcommand_body(train, [train_args] { return run_train(*train_args); });
}

}  // namespace animrt::cli
