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
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"
#include "seq_model_commands.hpp"
#include "seq_net_forward.hpp"
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

  add_seq_net_forwarders(*seq);
  add_seq_model_commands(*seq);
}

}  // namespace animrt::cli
