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
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/placement.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"
#include "option_checks.hpp"
#include "seq_model_commands.hpp"
#include "seq_net_forward.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct SeqArgs {
  std::string input;
  std::vector<std::string> inputs;
  std::string out;
  std::string clip;
  bool plain = false;
};

// A clip named after its file or folder; "walk/" names the folder too.
std::string clip_name(const std::string& path) {
  std::filesystem::path p(path);
  if (!p.has_filename()) p = p.parent_path();
  return p.filename().string();
}

// Several inputs become one sequence: each input is a clip of its own (named
// after its file or folder) or keeps its clips; all must share the first
// input's connectivity.
seqnet::MeshSequence read_inputs(const std::vector<std::string>& inputs) {
  seqnet::MeshSequence all = seqnet::read_mesh_sequence(inputs.front());
  if (inputs.size() == 1) return all;
  std::vector<seqnet::Clip> clips;
  auto add_clips = [&clips](const seqnet::MeshSequence& s, const std::string& path, int offset) {
    if (s.clips.empty()) {
      clips.push_back(seqnet::Clip{clip_name(path), offset, s.frame_count(), 0.0});
    }
    for (seqnet::Clip c : s.clips) {
      c.first += offset;
      clips.push_back(c);
    }
  };
  add_clips(all, inputs.front(), 0);
  for (std::size_t k = 1; k < inputs.size(); ++k) {
    seqnet::MeshSequence s = seqnet::read_mesh_sequence(inputs[k]);
    if (s.vertex_count() != all.vertex_count() || s.triangles != all.triangles) {
      throw InputError(Location{inputs[k], 0, 0}, "connectivity",
                       "differs from " + inputs.front() + " (" + std::to_string(s.vertex_count()) +
                           " vertices, " + std::to_string(s.triangles.size()) +
                           " triangles against " + std::to_string(all.vertex_count()) + " and " +
                           std::to_string(all.triangles.size()) + ")");
    }
    add_clips(s, inputs[k], all.frame_count());
    for (auto& f : s.frames) all.frames.push_back(std::move(f));
  }
  all.clips = std::move(clips);
  return all;
}

// Round trip per clip (or the whole range when it has none): absolute (the
// frames `seq reconstruct` writes) and per piece (each piece's centroid
// aligned first, the deformation features alone).
void print_round_trip(const seqnet::MeshSequence& sequence, int first, int count,
                      const seqnet::SequenceFeatures& features) {
  const seqnet::Reconstructor solver(features.rest, features.triangles);
  std::vector<seqnet::Clip> clips = features.clips;
  if (clips.empty()) clips.push_back(seqnet::Clip{"all", 0, count, 0.0});
  for (const auto& c : clips) {
    double mean = 0.0, max = 0.0, piece_mean = 0.0, piece_max = 0.0, turn = 0.0;
    for (int f = c.first; f < c.first + c.count; ++f) {
      const seqnet::FeatureFrame raw = features.raw(f);
      const seqnet::Positions& truth = sequence.frames[static_cast<std::size_t>(first + f)];
      seqnet::Positions got = solver.solve(raw);
      const seqnet::FrameError p =
          seqnet::error_up_to_translation(truth, got, solver.neighbourhood());
      seqnet::place(solver.neighbourhood(), got, features.placement[static_cast<std::size_t>(f)]);
      const seqnet::AbsoluteError e = seqnet::absolute_error(truth, got);
      mean += e.mean / c.count;
      max = std::max(max, e.max);
      piece_mean += p.mean / c.count;
      piece_max = std::max(piece_max, p.max);
      turn = std::max(turn, raw.topRows<3>().colwise().norm().maxCoeff());
    }
    // turn: the largest local rotation from the first frame, in degrees.
    std::printf(
        "  clip %-14s %3d frames  turn %4.0f deg  round trip mean %.2e  max %.2e  per piece mean "
        "%.2e  max %.2e (of the bounding-box diagonal)\n",
        c.name.c_str(), c.count, turn * 180.0 / 3.14159265358979323846, mean, max, piece_mean,
        piece_max);
  }
}

int run_features(const SeqArgs& a) {
  const seqnet::MeshSequence sequence = read_inputs(a.inputs);
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
          Location{a.inputs.front(), 0, 0}, "--clip",
          "no clip " + quote(a.clip) + " (clips: " + (names.empty() ? "none" : names) + ")");
    }
    first = found->first;
    count = found->count;
  }
  const seqnet::SequenceFeatures features =
      seqnet::compute_features(sequence, first, count, !a.plain);
  seqnet::write_feature_file(a.out, features);
  std::cout << (a.inputs.size() == 1 ? a.inputs.front()
                                     : std::to_string(a.inputs.size()) + " inputs")
            << ": " << sequence.vertex_count() << " vertices, " << sequence.triangles.size()
            << " triangles, frames " << first << ".." << first + count - 1 << " -> " << a.out
            << '\n';
  print_round_trip(sequence, first, count, features);
  return 0;
}

int run_reconstruct(const SeqArgs& a) {
  const seqnet::SequenceFeatures features = seqnet::read_feature_file(a.input);
  if (features.placement.empty()) {
    std::cerr << "warning: " << a.input
              << ": a version-1 feature file holds no placement (piece translations and root "
                 "trajectory); every piece is placed at its template vertex. Run seq features "
                 "again for absolute frames.\n";
  }
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
      ->add_option("SEQ", args->inputs,
                   "OBJ, MD2 or MD3 file (optionally .gz) or folder of OBJs; several become one "
                   "file with a clip per input")
      ->required();
  features->add_option("--out", args->out, "feature file to write")->required()->check(kOutputFile);
  features->add_option("--clip", args->clip, "only this clip's frames");
  features->add_flag("--plain", args->plain,
                     "per-vertex fits only (no exact round-trip correction)");
  set_subcommand_body(features, [args] {
    if (args->inputs.size() > 1 && !args->clip.empty()) {
      throw InputError(Location{args->inputs.front(), 0, 0}, "--clip",
                       "--clip takes one input, not " + std::to_string(args->inputs.size()));
    }
    return run_features(*args);
  });
  auto* reconstruct = seq->add_subcommand("reconstruct", "Mesh frames from a feature file");
  reconstruct->add_option("FEATURES", args->input, "feature file")->required();
  reconstruct->add_option("--out", args->out, "folder for frame_NNNN.obj")
      ->required()
      ->check(kOutputFolder);
  set_subcommand_body(reconstruct, [args] { return run_reconstruct(*args); });

  add_seq_net_forwarders(*seq);
  add_seq_model_commands(*seq);
}

}  // namespace animrt::cli
