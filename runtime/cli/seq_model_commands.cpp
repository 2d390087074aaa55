#include "seq_model_commands.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/generation.hpp"
#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/joint_csv.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/core/error.hpp"
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
    const seqnet::MeshSequence s = seqnet::read_mesh_sequence(file);
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
  seqnet::FrameMatrix frames(static_cast<Eigen::Index>(csv.joints.size()),
                             static_cast<Eigen::Index>(csv.rows.size()));
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    frames.col(static_cast<Eigen::Index>(r)) =
        Eigen::Map<const Eigen::VectorXd>(csv.rows[r].data(), frames.rows());
  }
  return frames;
}

struct GenerateArgs {
  std::string model;
  std::vector<std::string> init;
  std::string out;
  int frames = 32;
  std::optional<std::uint64_t> random_state;
};

int run_generate(const GenerateArgs& a) {
  const seqnet::ModelFile model = seqnet::read_model_file(a.model);
  if (model.shape.kind == seqnet::ModelKind::joints) {
    const seqnet::FrameMatrix initial = read_joint_frames(model, a.model, a.init, "--init", 1);
    if (initial.cols() >= model.shape.window) {
      throw InputError(Location{a.init[0], 0, 0}, "--init",
                       std::to_string(initial.cols()) + " initial frames, the model's window is " +
                           std::to_string(model.shape.window) + " frames");
    }
    seqnet::SeqNetInference net(model, a.model);
    seqnet::write_joint_csv(a.out, model.joint_names,
                            net.generate(initial, a.frames, a.random_state));
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
  const seqnet::ModelFile model = seqnet::read_model_file(a.model);
  seqnet::Completion c;
  if (model.shape.kind == seqnet::ModelKind::joints) {
    const seqnet::FrameMatrix keys = read_joint_frames(model, a.model, a.keys, "--keys", 2);
    seqnet::SeqNetInference net(model, a.model);
    c = net.complete(keys, std::vector<int>(static_cast<std::size_t>(keys.cols() - 1), a.gap),
                     a.options);
    seqnet::write_joint_csv(a.out, model.joint_names, c.frames);
  } else {
    if (a.keys.size() < 2) {
      throw InputError(Location{a.keys[0], 0, 0}, "--keys", "one key: give 2 or more");
    }
    const MeshFrames keys = read_mesh_frames(a.keys, "--keys");
    const seqnet::FrameMatrix features =
        seqnet::mesh_features(model, a.model, keys.frames, keys.triangles);
    seqnet::SeqNetInference net(model, a.model);
    c = net.complete(features, std::vector<int>(keys.frames.size() - 1, a.gap), a.options);
    // Keys as read, the in-betweens reconstructed.
    seqnet::MeshSequence out;
    out.triangles = keys.triangles;
    for (std::size_t k = 0; k < keys.frames.size(); ++k) {
      if (k > 0) {
        const seqnet::FrameMatrix gap =
            c.frames.middleCols(static_cast<Eigen::Index>(k - 1) * (a.gap + 1) + 1, a.gap);
        for (seqnet::Positions& p : seqnet::mesh_positions(model, gap)) {
          out.frames.push_back(std::move(p));
        }
      }
      out.frames.push_back(keys.frames[k]);
    }
    seqnet::write_obj_sequence(a.out, out);
  }
  print_report(c.gaps, a.options.threshold);
  std::cout << a.model << ": " << c.gaps.size() + 1 << " keys, " << c.frames.cols()
            << " frames -> " << a.out
            << (model.shape.kind == seqnet::ModelKind::mesh ? "/frame_*.obj" : "") << '\n';
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
  generate->add_option("--frames", g->frames, "frames to generate")
      ->check(CLI::Range(1, 1000000));
  generate
      ->add_option("--out", g->out,
                   "mesh model: folder for frame_NNNN.obj; joint model: CSV file to write")
      ->required();
  generate->add_option("--random-state", g->random_state,
                       "draw the initial LSTM states from this seed");
  set_subcommand_body(generate, [g] { return run_generate(*g); });

  auto c = std::make_shared<CompleteArgs>();
  auto* complete =
      seq.add_subcommand("complete", "Complete the frames between keys (forward and backward "
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
      ->check(CLI::Range(1e-12, 10.0));
  complete->add_option("--retries", c->options.retries, "runs with random initial states")
      ->check(CLI::Range(0, 100000));
  complete->add_option("--seed", c->options.seed, "seed of the random initial states");
  set_subcommand_body(complete, [c] { return run_complete(*c); });
}

}  // namespace animrt::cli
