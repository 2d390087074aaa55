// The commands of the sequence network, which need libtorch: `train` and
// `generate`. They live in their own executable, animrt-seqnet, so that the
// runtime binary (animrt) neither loads libtorch (half a second and 130 MB
// at every start) nor needs it on a robot's controller; `animrt seq train`
// and `animrt seq generate` hand over to it (runtime/cli/seq_net_forward.cpp).

#include "seq_net_commands.hpp"

#include <array>
#include <cstdint>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../subcommand.hpp"
#include "animrt/controllers/seqnet/generation.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/training.hpp"
#include "animrt/core/error.hpp"

namespace animrt::cli {
namespace {

int run_train(const seqnet::TrainOptions& o) {
  const seqnet::TrainResult r = seqnet::train(o, std::cout);
  std::cout << "trained " << r.run << " iterations (" << r.iterations << " in all) in " << r.seconds
            << " s\n";
  return 0;
}

struct GenerateArgs {
  std::string model;
  std::vector<std::string> init;
  std::string out;
  int frames = 32;
  std::optional<std::uint64_t> random_state;
  int threads = 1;
};

int run_generate(const GenerateArgs& a) {
  const seqnet::ModelFile model = seqnet::read_model_file(a.model);
  std::vector<seqnet::Positions> initial;
  std::vector<std::array<int, 3>> triangles;
  for (const std::string& file : a.init) {
    const seqnet::MeshSequence m = seqnet::read_mesh_sequence(file);
    if (m.frames.empty()) throw InputError(Location{file, 0, 0}, "--init", "no frame");
    seqnet::check_model_mesh(model, a.model, m.vertex_count(), m.triangles);
    initial.push_back(m.frames.front());
    triangles = m.triangles;
  }
  seqnet::GenerateOptions o;
  o.frames = a.frames;
  o.random_state = a.random_state;
  o.threads = a.threads;
  seqnet::MeshSequence out;
  out.triangles = triangles;
  out.frames = seqnet::generate_mesh(model, a.model, initial, triangles, o);
  seqnet::write_obj_sequence(a.out, out);
  std::cout << a.model << ": " << initial.size() << " initial + " << a.frames
            << " generated frames -> " << a.out << "/frame_*.obj\n";
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
  train->add_option("--out", train_args->out, "model file (also OUT.ckpt and OUT.svg)")->required();
  train->add_option("--iterations", train_args->iterations, "total iterations")
      ->check(CLI::Range(1, 100000000));
  train->add_option("--seed", train_args->seed, "seed for the split, the batches and the weights");
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
      ->check(CLI::PositiveNumber);
  train->add_option("--checkpoint-every", train_args->checkpoint_every, "iterations")
      ->check(CLI::Range(1, 100000000));
  train->add_option("--report-every", train_args->report_every, "iterations per progress line")
      ->check(CLI::Range(1, 100000000));
  train->add_option("--latent", train_args->latent, "latent size")->check(CLI::Range(1, 4096));
  train->add_option("--hidden", train_args->hidden, "LSTM hidden units")
      ->check(CLI::Range(1, 4096));
  train->add_option("--lstm-layers", train_args->lstm_layers, "LSTM layers")
      ->check(CLI::Range(1, 8));
  train->add_option("--dense-width", train_args->dense_width, "joint models: hidden layer width")
      ->check(CLI::Range(1, 4096));
  train->add_option("--kl-weight", train_args->kl_weight, "0 turns L_KL off (ablation)")
      ->check(CLI::Range(0.0, 100.0));
  train->add_flag("!--unidirectional", train_args->bidirectional,
                  "forward chain only, no L_bidir (ablation)");
  set_subcommand_body(train, [train_args] { return run_train(*train_args); });

  auto gen_args = std::make_shared<GenerateArgs>();
  auto* generate = seq->add_subcommand("generate", "Generate a mesh sequence from initial frames");
  generate->add_option("MODEL", gen_args->model, "model file (animrt seq train)")->required();
  generate->add_option("--init", gen_args->init, "one or more initial frames (OBJ)")
      ->required()
      ->expected(1, 8);
  generate->add_option("--frames", gen_args->frames, "frames to generate")
      ->check(CLI::Range(1, 1000000));
  generate->add_option("--out", gen_args->out, "folder for frame_NNNN.obj")->required();
  generate->add_option("--random-state", gen_args->random_state,
                       "draw the initial LSTM states from this seed");
  generate->add_option("--threads", gen_args->threads, "libtorch threads")
      ->check(CLI::Range(1, 256));
  set_subcommand_body(generate, [gen_args] { return run_generate(*gen_args); });
}

}  // namespace animrt::cli
