// `animrt seq corpus` (see seq_corpus_command.hpp).

#include "seq_corpus_command.hpp"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>

#include "animrt/core/error.hpp"
#include "animrt/learn/seq_corpus/generator.hpp"
#include "data_dir.hpp"
#include "option_checks.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct SeqCorpusArgs {
  std::string out;
  std::string model = "quadruped";
  std::string configs = data_dir();
  std::vector<std::string> gaits;
  std::vector<double> froude;
  std::vector<double> turns{0.0};
  int frames = 64;
  int vertices = 1000;
  int seeds = 3;
  std::uint64_t seed = 1;
  double fps = 25.0;
  bool quiet = false;
};

bool is_preset(const std::string& model) { return model == "horse" || model == "quadruped"; }

int run_seq_corpus(const SeqCorpusArgs& a) {
  learn::seq_corpus::CorpusOptions o;
  if (is_preset(a.model)) {
    o = learn::seq_corpus::model_preset(a.model, a.configs);
  } else {
    o.model_file = a.model;
    if (a.model.size() < 4 || a.model.compare(a.model.size() - 4, 4, ".xml") != 0) {
      std::cerr << "error: --model " << a.model
                << ": expected horse, quadruped or an MJCF file (.xml)\n";
      return kExitUsage;
    }
    if (a.gaits.empty() || a.froude.empty()) {
      std::cerr << "error: --model " << a.model << " needs --gait and --froude\n";
      return kExitUsage;
    }
  }
  if (!a.gaits.empty()) o.gaits = a.gaits;
  if (!a.froude.empty()) o.froude = a.froude;
  o.turns = a.turns;
  o.seeds = a.seeds;
  o.first_seed = a.seed;
  o.vertices = a.vertices;
  o.walk.frames = a.frames;
  o.walk.fps = a.fps;
  if (!a.quiet) o.log = [](const std::string& s) { std::cerr << s << '\n'; };
  const auto t0 = std::chrono::steady_clock::now();
  const auto s = learn::seq_corpus::generate_corpus(a.out, o);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "wrote %d sequences (%ld frames, %d vertices, %d triangles, %d fell) to %s in %.1f s\n",
      s.sequences, s.frames, s.vertices, s.triangles, s.fell, a.out.c_str(), took);
  return 0;
}

}  // namespace

void add_seq_corpus_command(CLI::App& seq) {
  auto a = std::make_shared<SeqCorpusArgs>();
  auto* c = seq.add_subcommand("corpus",
                               "Generate mesh sequences: a skinned model walking gaits on MuJoCo");
  c->add_option("--out", a->out, "output folder")->required()->check(kOutputFolder);
  c->add_option("--model", a->model, "horse, quadruped (files under --configs) or MODEL.xml")
      ->capture_default_str();
  c->add_option("--configs", a->configs, "folder with models/ and gaits/ for a named model")
      ->capture_default_str();
  c->add_option("--gait", a->gaits, "gait file (repeatable; default: the model's gaits)");
  c->add_option("--froude", a->froude, "Froude numbers (default: around the gaits' own)")
      ->delimiter(',')
      ->check(kPositiveNumber);
  c->add_option("--turn", a->turns,
                "turn rates (rad/s) given to the gait through steer(); a gait that cannot be "
                "steered walks straight, the index records what it achieved")
      ->delimiter(',')
      ->capture_default_str();
  c->add_option("--frames", a->frames, "frames per sequence")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  c->add_option("--vertices", a->vertices, "skin vertices, roughly")
      ->check(CLI::Range(100, 50000))
      ->capture_default_str();
  c->add_option("--seed", a->seed, "first seed")->capture_default_str()->check(kSeed);
  c->add_option("--seeds", a->seeds, "seeds per configuration")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  c->add_option("--fps", a->fps, "frame rate (a whole number of physics steps per frame)")
      ->check(kPositiveNumber)
      ->capture_default_str();
  c->add_flag("--quiet", a->quiet, "no progress lines");
  set_subcommand_body(c, [a] { return run_seq_corpus(*a); });
}

}  // namespace animrt::cli
