#include "seq_model_commands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/generation.hpp"
#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/joint_csv.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/output_check.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "animrt/learn/seqnet/evaluation.hpp"
#include "animrt/learn/seqnet/held_out.hpp"
#include "option_checks.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct MeshFrames {
  std::vector<seqnet::Positions> frames;
  std::vector<std::array<int, 3>> triangles;
};

// The first frame of each OBJ (or other mesh) file.
MeshFrames read_mesh_frames(const std::vector<std::string>& files, const std::string& option) {
  MeshFrames m;
  for (const std::string& file : files) {
    const seqnet::MeshSequence s = seqnet::read_mesh_pose(file);
    if (s.frames.empty()) throw InputError(Location{file, 0, 0}, option, "no frame");
    m.frames.push_back(s.frames.front());
    m.triangles = s.triangles;
  }
  return m;
}

// The rows of a joint CSV as columns, checked against the model's joints.
seqnet::FrameMatrix read_joint_frames(const seqnet::ModelFile& model, const std::string& model_path,
                                      const std::vector<std::string>& files,
                                      const std::string& option, int at_least) {
  if (files.size() != 1) {
    throw InputError(Location{files[1], 0, 0}, option,
                     "a joint model takes one CSV with one row per frame");
  }
  const seqnet::JointCsv csv = seqnet::read_joint_csv(files[0]);
  seqnet::check_model_joints(model, model_path, csv.joints);
  if (static_cast<int>(csv.rows.size()) < at_least) {
    throw InputError(Location{files[0], 0, 0}, option,
                     std::to_string(csv.rows.size()) + " rows, at least " +
                         std::to_string(at_least) + " needed");
  }
  // A pose far outside what the model was trained on is not one it can
  // continue or join: its output there means nothing (and 1e300 rad came
  // back as a written frame). One range's width beyond either end is
  // allowed for keys a little past the training data.
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    for (std::size_t j = 0; j < csv.joints.size(); ++j) {
      const double lo = model.low[j], hi = model.high[j], width = hi - lo;
      const double v = csv.rows[r][j];
      if (v >= lo - width && v <= hi + width) continue;
      throw InputError(Location{files[0], csv.lines[r], 0}, csv.joints[j],
                       format_number(v) + " is far outside the range " + model_path +
                           " was trained on (" + format_number(lo) + " to " + format_number(hi) +
                           "; a pose at most the range's width beyond it is taken)");
    }
  }
  seqnet::FrameMatrix frames(static_cast<Eigen::Index>(csv.joints.size()),
                             static_cast<Eigen::Index>(csv.rows.size()));
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    frames.col(static_cast<Eigen::Index>(r)) =
        Eigen::Map<const Eigen::VectorXd>(csv.rows[r].data(), frames.rows());
  }
  return frames;
}

// A mesh frame with a non-finite position is refused before any file is
// written (a viewer would draw nothing, or everything at infinity).
void require_finite_mesh(const std::vector<seqnet::Positions>& frames, const std::string& model) {
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].allFinite()) continue;
    throw InputError(Location{model, 0, 0}, "output",
                     "the model computed a non-finite vertex position at frame " +
                         std::to_string(f) + "; nothing was written");
  }
}

struct GenerateArgs {
  std::string model;
  std::vector<std::string> init;
  std::string out;
  int frames = 32;
  std::optional<std::uint64_t> random_state;
};

// A joint model writes a CSV file, a mesh model a folder of frames.
bool out_ok(const seqnet::ModelFile& model, const std::string& out) {
  return output_option_ok(
      "--out", out, model.shape.kind == seqnet::ModelKind::joints ? kOutputFile : kOutputFolder);
}

int run_generate(const GenerateArgs& a) {
  const seqnet::ModelFile model = seqnet::read_checked_model(a.model);
  if (!out_ok(model, a.out)) return kExitUsage;
  if (model.shape.kind == seqnet::ModelKind::joints) {
    const seqnet::FrameMatrix initial = read_joint_frames(model, a.model, a.init, "--init", 1);
    if (initial.cols() >= model.shape.window) {
      throw InputError(Location{a.init[0], 0, 0}, "--init",
                       std::to_string(initial.cols()) + " initial frames, the model's window is " +
                           std::to_string(model.shape.window) + " frames");
    }
    seqnet::SeqNetInference net(model, a.model);
    const seqnet::FrameMatrix frames = net.generate(initial, a.frames, a.random_state);
    seqnet::require_finite_frames(frames, a.model, model.joint_names);
    seqnet::write_joint_csv(a.out, model.joint_names, frames);
    std::cout << a.model << ": " << initial.cols() << " initial + " << a.frames
              << " generated frames -> " << a.out << '\n';
    return 0;
  }
  const MeshFrames init = read_mesh_frames(a.init, "--init");
  seqnet::GenerateOptions o;
  o.frames = a.frames;
  o.random_state = a.random_state;
  seqnet::MeshSequence out;
  out.triangles = init.triangles;
  out.frames = seqnet::generate_mesh(model, a.model, init.frames, init.triangles, o);
  require_finite_mesh(out.frames, a.model);
  seqnet::write_obj_sequence(a.out, out);
  std::cout << a.model << ": " << init.frames.size() << " initial + " << a.frames
            << " generated frames -> " << a.out << "/frame_*.obj\n";
  return 0;
}

struct CompleteArgs {
  std::string model;
  std::vector<std::string> keys;
  std::string out;
  int gap = 9;
  seqnet::CompletionOptions options;
};

void print_report(const std::vector<seqnet::GapReport>& gaps, double threshold) {
  int at = 0;
  for (std::size_t g = 0; g < gaps.size(); ++g) {
    const seqnet::GapReport& r = gaps[g];
    char line[256];
    if (r.merged) {
      std::snprintf(line, sizeof line,
                    "gap %zu (keys %zu-%zu, %d frames): merged at frame %d (output frame %d), "
                    "difference %.2f %%, %d %s",
                    g + 1, g + 1, g + 2, r.gap, r.frame, at + r.frame, 100.0 * r.difference,
                    r.tries, r.tries == 1 ? "try" : "tries");
    } else {
      std::snprintf(line, sizeof line,
                    "gap %zu (keys %zu-%zu, %d frames): not merged below %g %%, best difference "
                    "%.2f %% at frame %d (output frame %d) used, %d tries",
                    g + 1, g + 1, g + 2, r.gap, 100.0 * threshold, 100.0 * r.difference, r.frame,
                    at + r.frame, r.tries);
    }
    std::cout << line << '\n';
    at += r.gap + 1;
  }
}

int run_complete(const CompleteArgs& a) {
  const seqnet::ModelFile model = seqnet::read_checked_model(a.model);
  if (!out_ok(model, a.out)) return kExitUsage;
  seqnet::Completion c;
  if (model.shape.kind == seqnet::ModelKind::joints) {
    const seqnet::FrameMatrix keys = read_joint_frames(model, a.model, a.keys, "--keys", 2);
    seqnet::SeqNetInference net(model, a.model);
    c = net.complete(keys, std::vector<int>(static_cast<std::size_t>(keys.cols() - 1), a.gap),
                     a.options);
    seqnet::require_finite_frames(c.frames, a.model, model.joint_names);
    seqnet::write_joint_csv(a.out, model.joint_names, c.frames);
  } else {
    if (a.keys.size() < 2) {
      throw InputError(Location{a.keys[0], 0, 0}, "--keys", "one key: give 2 or more");
    }
    const MeshFrames keys = read_mesh_frames(a.keys, "--keys");
    const seqnet::FrameMatrix features =
        seqnet::mesh_features(model, a.model, keys.frames, keys.triangles, a.gap + 1.0);
    seqnet::SeqNetInference net(model, a.model);
    c = net.complete(features, std::vector<int>(keys.frames.size() - 1, a.gap), a.options);
    // Keys as read, the in-betweens reconstructed and placed between them.
    seqnet::MeshSequence out;
    out.triangles = keys.triangles;
    out.frames = seqnet::completed_mesh(model, keys.frames, features, c, a.gap);
    require_finite_mesh(out.frames, a.model);
    seqnet::write_obj_sequence(a.out, out);
  }
  print_report(c.gaps, a.options.threshold);
  if (const std::string w = seqnet::interpolation_warning(model, a.model); !w.empty()) {
    std::cerr << w << '\n';
  }
  std::cout << a.model << ": " << c.gaps.size() + 1 << " keys, " << c.frames.cols() << " frames -> "
            << a.out << (model.shape.kind == seqnet::ModelKind::mesh ? "/frame_*.obj" : "") << '\n';
  return 0;
}

struct EvaluateArgs {
  std::string model;
  std::string data;
  seqnet::EvaluationOptions options;
};

int run_evaluate(const EvaluateArgs& a) {
  const seqnet::ModelFile model = seqnet::read_checked_model(a.model);
  const seqnet::SequenceFeatures data = seqnet::read_feature_file(a.data);
  seqnet::EvaluationOptions options = a.options;
  options.data_path = a.data;
  const seqnet::Evaluation e = seqnet::evaluate(model, a.model, data, options);
  int held = 0;
  for (const auto& p : e.pieces) held += p.count;
  char how[64];
  if (options.held_out_clips.empty()) {
    std::snprintf(how, sizeof how, "seed %llu, %g %%", static_cast<unsigned long long>(model.seed),
                  100.0 * options.held_out);
  } else {
    std::snprintf(how, sizeof how, "the clips named");
  }
  std::printf("%s: %llu iterations; held out (%s): %d of %zu frames of %s in %zu pieces\n",
              a.model.c_str(), static_cast<unsigned long long>(model.iteration), how, held,
              data.frames.size(), a.data.c_str(), e.pieces.size());
  for (const auto& p : e.pieces) {
    std::printf("  %s frames %d..%d\n", p.name.c_str(), p.first, p.first + p.count - 1);
  }
  std::printf(
      "mean per-vertex error after removing each piece's mean offset, in the data's units "
      "(mean bounding-box diagonal %.4g)\n",
      e.diagonal);
  for (const auto& r : e.generation) {
    std::printf(
        "generate from %d initial frame%s, frame %2d (%d starts): learned %.4g  linear "
        "extrapolation in feature space %.4g\n",
        r.initial, r.initial == 1 ? " " : "s", r.horizon, r.frames, r.learned, r.extrapolated);
  }
  const seqnet::CompletionRow& c = e.completion;
  if (c.frames > 0) {
    const double best = std::min(c.feature_linear, c.vertex_linear);
    std::printf(
        "complete %d gaps of %d frames (%d merged below %g %%): learned %.4g  linear in "
        "feature space %.4g  linear in vertex space %.4g  (learned %.1f %% %s the best "
        "interpolation)\n",
        c.gaps, a.options.gap, c.merged, 100.0 * a.options.completion.threshold, c.learned,
        c.feature_linear, c.vertex_linear, 100.0 * std::abs(1.0 - c.learned / best),
        c.learned <= best ? "below" : "above");
  }
  if (c.placed_frames > 0) {
    std::printf(
        "complete the key meshes as seq complete does, placed, nothing aligned (mean vertex "
        "error as a fraction of the bounding-box diagonal, %d frames): learned %.2f %%  linear "
        "vertex interpolation %.2f %%  (%s than linear vertex interpolation)\n",
        c.placed_frames, 100.0 * c.placed, 100.0 * c.placed_vertex_linear,
        seqnet::compared_with(c.placed, c.placed_vertex_linear).c_str());
  }
  if (!e.change_generated.empty()) {
    std::printf(
        "change per frame |x(t+1) - x(t)| / |x(t)| (normalised features), %d starts, "
        "held-out frames %.4g; generated t = 1..%zu:",
        e.change_starts, e.change_truth, e.change_generated.size());
    for (double v : e.change_generated) std::printf(" %.4g", v);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

void add_seq_model_commands(CLI::App& seq) {
  auto g = std::make_shared<GenerateArgs>();
  auto* generate = seq.add_subcommand(
      "generate", "Generate a mesh sequence or joint trajectory from initial frames");
  generate->add_option("MODEL", g->model, "model file (animrt seq train)")->required();
  generate
      ->add_option("--init", g->init,
                   "mesh model: 1 or more initial frames (OBJ); joint model: one CSV, a row per "
                   "initial frame")
      ->required()
      ->expected(1, 8);
  generate->add_option("--frames", g->frames, "frames to generate")->check(CLI::Range(1, 1000000));
  generate
      ->add_option("--out", g->out,
                   "mesh model: folder for frame_NNNN.obj; joint model: CSV file to write")
      ->required();
  generate
      ->add_option("--random-state", g->random_state, "draw the initial LSTM states from this seed")
      ->check(kSeed);
  set_subcommand_body(generate, [g] { return run_generate(*g); });

  auto c = std::make_shared<CompleteArgs>();
  auto* complete = seq.add_subcommand("complete",
                                      "Complete the frames between keys (forward and backward "
                                      "chains merged where they meet)");
  complete->add_option("MODEL", c->model, "model file (animrt seq train)")->required();
  complete
      ->add_option("--keys", c->keys,
                   "mesh model: 2 or more key frames (OBJ); joint model: one CSV, a row per key")
      ->required();
  complete->add_option("--gap", c->gap, "frames between consecutive keys")
      ->required()
      ->check(CLI::Range(1, 100000));
  complete
      ->add_option("--out", c->out,
                   "mesh model: folder for frame_NNNN.obj; joint model: CSV file to write")
      ->required();
  complete
      ->add_option("--threshold", c->options.threshold,
                   "largest difference to merge at: RMS over the features, as a fraction of "
                   "each one's training range")
      ->check(FiniteRange(1e-12, 10.0));
  complete->add_option("--retries", c->options.retries, "runs with random initial states")
      ->check(CLI::Range(0, 100000));
  complete->add_option("--seed", c->options.seed, "seed of the random initial states")
      ->check(kSeed);
  complete->add_flag("!--hand-over", c->options.blend,
                     "forward frames up to where the chains meet, backward frames after (the "
                     "paper) instead of blending the chains");
  set_subcommand_body(complete, [c] { return run_complete(*c); });

  auto ev = std::make_shared<EvaluateArgs>();
  auto* evaluate = seq.add_subcommand(
      "evaluate",
      "Measure a mesh model on the held-out frames of its training feature file: "
      "generation, completion, change per frame");
  evaluate->add_option("MODEL", ev->model, "mesh model file (animrt seq train)")->required();
  evaluate->add_option("FEATURES", ev->data, "the feature file it was trained on")->required();
  auto* fraction =
      evaluate->add_option("--held-out", ev->options.held_out, "the trainer's held-out fraction")
          ->check(FiniteRange(0.0, 1.0));
  evaluate
      ->add_option("--held-out-clip", ev->options.held_out_clips,
                   "the clip the model was trained with held out whole (seq train "
                   "--held-out-clip) instead of the fraction; repeatable")
      ->excludes(fraction);
  evaluate->add_option("--gap", ev->options.gap, "completion: frames between keys")
      ->check(CLI::Range(1, 100000));
  evaluate
      ->add_option("--threshold", ev->options.completion.threshold, "completion: merge threshold")
      ->check(FiniteRange(1e-12, 10.0));
  evaluate->add_option("--retries", ev->options.completion.retries, "completion: random retries")
      ->check(CLI::Range(0, 100000));
  evaluate
      ->add_option("--change-frames", ev->options.change_frames,
                   "frames generated for the change per frame (0: skip)")
      ->check(CLI::Range(0, 100000));
  set_subcommand_body(evaluate, [ev] { return run_evaluate(*ev); });
}

}  // namespace animrt::cli
