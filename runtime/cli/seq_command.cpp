// The seq subcommand: deformation features of a mesh sequence to a feature
// file (with the round-trip error per clip), and a feature file back to OBJ
// frames.

#include "seq_command.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/generation.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/controllers/seqnet/training.hpp"
#include "animrt/core/error.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct SeqArgs {
  std::string input;
  std::string out;
  std::string clip;
  bool plain = false;
};

int run_features(const SeqArgs& a) {
  const seqnet::MeshSequence sequence = seqnet::read_mesh_sequence(a.input);
  int first = 0, count = sequence.frame_count();
  if (!a.clip.empty()) {
    const seqnet::Clip* found = nullptr;
    for (const auto& c : sequence.clips) {
      if (c.name == a.clip) found = &c;
    }
    if (found == nullptr) {
      std::string names;
      for (const auto& c : sequence.clips) names += (names.empty() ? "" : ", ") + c.name;
      throw InputError(
          Location{a.input, 0, 0}, "--clip",
          "no clip \"" + a.clip + "\" (clips: " + (names.empty() ? "none" : names) + ")");
    }
    first = found->first;
    count = found->count;
  }
  const seqnet::SequenceFeatures features =
      seqnet::compute_features(sequence, first, count, !a.plain);
  seqnet::write_feature_file(a.out, features);
  std::cout << a.input << ": " << sequence.vertex_count() << " vertices, "
            << sequence.triangles.size() << " triangles, frames " << first << ".."
            << first + count - 1 << " -> " << a.out << '\n';
  // Round trip per clip (or the whole range when it has none).
  const seqnet::Reconstructor solver(features.rest, features.triangles);
  std::vector<seqnet::Clip> clips = features.clips;
  if (clips.empty()) clips.push_back(seqnet::Clip{"all", 0, count, 0.0});
  for (const auto& c : clips) {
    double mean = 0.0, max = 0.0, turn = 0.0;
    for (int f = c.first; f < c.first + c.count; ++f) {
      const seqnet::FeatureFrame raw = features.raw(f);
      const seqnet::FrameError e =
          seqnet::error_up_to_translation(sequence.frames[static_cast<std::size_t>(first + f)],
                                          solver.solve(raw), solver.neighbourhood());
      mean += e.mean / c.count;
      max = std::max(max, e.max);
      turn = std::max(turn, raw.topRows<3>().colwise().norm().maxCoeff());
    }
    // turn: the largest local rotation from the first frame, in degrees.
    std::printf(
        "  clip %-14s %3d frames  turn %4.0f deg  round trip mean %.2e  max %.2e (of the "
        "bounding-box diagonal)\n",
        c.name.c_str(), c.count, turn * 180.0 / 3.14159265358979323846, mean, max);
  }
  return 0;
}

int run_reconstruct(const SeqArgs& a) {
  const seqnet::SequenceFeatures features = seqnet::read_feature_file(a.input);
  const std::vector<seqnet::Positions> frames = seqnet::reconstruct_all(features);
  seqnet::MeshSequence out;
  out.triangles.assign(features.triangles.begin(), features.triangles.end());
  out.frames = std::move(frames);
  seqnet::write_obj_sequence(a.out, out);
  std::cout << a.input << ": " << out.frames.size() << " frames -> " << a.out << "/frame_*.obj\n";
  return 0;
}

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

void add_seq_command(CLI::App& seq_group) {
  CLI::App* seq = &seq_group;
  auto args = std::make_shared<SeqArgs>();
  auto* features = seq->add_subcommand("features", "Deformation features of a mesh sequence");
  features
      ->add_option("SEQ", args->input, "OBJ, MD2 or MD3 file (optionally .gz) or folder of OBJs")
      ->required();
  features->add_option("--out", args->out, "feature file to write")->required();
  features->add_option("--clip", args->clip, "only this clip's frames");
  features->add_flag("--plain", args->plain,
                     "per-vertex fits only (no exact round-trip correction)");
  set_subcommand_body(features, [args] { return run_features(*args); });
  auto* reconstruct = seq->add_subcommand("reconstruct", "Mesh frames from a feature file");
  reconstruct->add_option("FEATURES", args->input, "feature file")->required();
  reconstruct->add_option("--out", args->out, "folder for frame_NNNN.obj")->required();
  set_subcommand_body(reconstruct, [args] { return run_reconstruct(*args); });

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
