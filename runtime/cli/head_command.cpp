// The head subcommands: features, corpus generation, training, synthesis,
// evaluation and the paper's Table 1.

#include "head_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <set>
#include <string>

#include "animrt/controllers/head/model.hpp"
#include "animrt/controllers/head/synthesis.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/head/corpus.hpp"
#include "animrt/learn/head/evaluation.hpp"
#include "animrt/learn/head/trainer.hpp"
#include "animrt/learn/head_corpus/generator.hpp"
#include "option_checks.hpp"
#include "output_file.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

using namespace animrt::head;

struct HeadArgs {
  std::string in, out, model, corpus, topology = "LR";
  int utterances = 60, speakers = 4, clusters = 16, states = 3, mixtures = 2, iterations = 10;
  std::uint64_t seed = 1;
  double train_fraction = 0.8;
  double noise_deg = -1;
  double shrink = -1;
  bool quiet = false;
};

TrainOptions train_options(const HeadArgs& a) {
  TrainOptions o;
  o.clusters = a.clusters;
  o.states = a.states;
  o.mixtures = a.mixtures;
  o.iterations = a.iterations;
  o.shrink = a.shrink;
  o.topology = a.topology == "EG" ? Topology::kErgodic : Topology::kLeftToRight;
  if (!a.quiet) o.log = [](const std::string& s) { std::cerr << s << '\n'; };
  return o;
}

// A sound shorter than one analysis window gives no frame, so no pose:
// said, rather than an empty file written as if all went well.
void require_frames(const std::string& path, std::size_t frames, const FeatureConfig& config) {
  if (frames > 0) return;
  throw InputError(Location{path, 0, 0}, "",
                   "the sound is shorter than one analysis window (" +
                       std::to_string(std::lround(config.window_s * 1000)) +
                       " ms), so it gives no head motion");
}

int run_features(const HeadArgs& a) {
  const FeatureTrack t = extract_features_file(a.in, FeatureConfig{});
  require_frames(a.in, t.size(), FeatureConfig{});
  write_features_csv(a.out, t);
  std::size_t voiced = 0;
  for (const auto& f : t.raw) voiced += f.voiced ? 1 : 0;
  std::cout << "wrote " << a.out << ": " << t.size() << " frames at " << t.frame_rate_hz << " Hz, "
            << voiced << " voiced\n";
  return 0;
}

int run_corpus(const HeadArgs& a) {
  learn::head_corpus::CorpusOptions o;
  o.utterances = a.utterances;
  o.speakers = a.speakers;
  o.seed = a.seed;
  if (!a.quiet) o.log = [](const std::string& s) { std::cerr << s << '\n'; };
  learn::head_corpus::generate_corpus(a.out, o);
  std::cout << "wrote " << a.utterances << " utterances to " << a.out << '\n';
  return 0;
}

int run_train(const HeadArgs& a) {
  const auto split = split_corpus(list_corpus(a.corpus), a.train_fraction, a.seed);
  const FeatureConfig fc;
  const auto train = prepare_corpus(split.train, fc);
  const HeadModel model = train_model(train, fc, train_options(a));
  save_model(a.out, model);
  std::cout << "wrote " << a.out << " (K=" << a.clusters << " S=" << a.states << " M=" << a.mixtures
            << " " << a.topology << ", trained on " << train.size() << " of "
            << split.train.size() + split.test.size() << " utterances)\n";
  return 0;
}

int run_synth(const HeadArgs& a) {
  HeadModel model = load_model(a.model);
  if (a.noise_deg >= 0) model.smoothing.noise_deg = a.noise_deg;
  const PoseTrack poses = synthesize(model, load_audio(a.in, model.features.sample_rate));
  require_frames(a.in, poses.size(), model.features);
  write_euler_csv(a.out, poses);
  std::cout << "wrote " << a.out << ": " << poses.size() << " poses at "
            << model.smoothing.output_rate_hz << " Hz\n";
  return 0;
}

void print_eval(const Evaluation& e) {
  std::printf(
      "test utterances %d\nmean distance  %.2f deg (std %.2f)\nfirst CCA      %.3f (std %.3f)\n"
      "mean-pose baseline distance %.2f deg (std %.2f), first CCA %.3f (std %.3f)\n",
      e.utterances, e.distance_deg.mean, e.distance_deg.std, e.cca.mean, e.cca.std,
      e.baseline_distance_deg.mean, e.baseline_distance_deg.std, e.baseline_cca.mean,
      e.baseline_cca.std);
}

int run_eval(const HeadArgs& a) {
  const HeadModel model = load_model(a.model);
  const std::set<std::string> trained(model.training_utterances.begin(),
                                      model.training_utterances.end());
  std::vector<Utterance> train, test;
  for (const auto& u : list_corpus(a.corpus)) (trained.count(u.name) ? train : test).push_back(u);
  if (test.empty())
    throw InputError(Location{a.corpus, 0, 0}, "",
                     "every utterance of the corpus was used for training; nothing to test on");
  const auto prepared_test = prepare_corpus(test, model.features);
  const Eigen::Vector3d baseline =
      train.empty() ? mean_pose(prepared_test) : mean_pose(prepare_corpus(train, model.features));
  print_eval(evaluate(model, prepared_test, baseline));
  return 0;
}

int run_table(const HeadArgs& a) {
  OutputFile out;  // opened before the hours of training, written at the end
  if (!a.out.empty() && !out.open(a.out)) {
    throw cannot_write("--out", a.out, out.error);
  }
  const auto split = split_corpus(list_corpus(a.corpus), a.train_fraction, a.seed);
  const FeatureConfig fc;
  const auto t0 = std::chrono::steady_clock::now();
  const auto train = prepare_corpus(split.train, fc);
  const auto test = prepare_corpus(split.test, fc);
  std::cerr << "features: " << train.size() << " training and " << test.size()
            << " test utterances\n";
  TrainOptions base = train_options(a);
  base.log = nullptr;
  const auto rows = run_table(train, test, fc, base, [&](const TableRow& r) {
    if (!a.quiet) {
      std::cerr << "K=" << r.config.clusters << " S=" << r.config.states
                << " M=" << r.config.mixtures << " " << topology_name(r.config.topology) << ": D "
                << r.result.distance_deg.mean << " CCA " << r.result.cca.mean << '\n';
    }
  });
  const std::string table = format_table(rows);
  std::cout << table;
  if (out.is_open() && !out.write(table)) {
    throw cannot_write("--out", a.out, out.error);
  }
  std::cerr << "took "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()
            << " s\n";
  return 0;
}

void add_train_options(CLI::App* c, HeadArgs& a) {
  c->add_option("--clusters,-K", a.clusters, "codebook size K")->check(CLI::Range(1, 256));
  c->add_option("--states,-S", a.states, "HMM states S")->check(CLI::Range(1, 20));
  c->add_option("--mixtures,-M", a.mixtures, "Gaussian mixtures per state M")
      ->check(CLI::Range(1, 16));
  c->add_option("--topology", a.topology, "LR (left-to-right) or EG (ergodic)")
      ->check(CLI::IsMember({"LR", "EG"}));
  c->add_option("--iterations", a.iterations, "Baum-Welch iterations at most")
      ->check(CLI::Range(0, 200));
  c->add_option("--train-fraction", a.train_fraction, "share of the corpus for training")
      ->check(FiniteRange(0.05, 1.0));
  c->add_option("--shrink", a.shrink,
                "output poses toward the mean pose: factor in [0, 1] (1: the paper), "
                "negative: chosen on the training data")
      ->check(FiniteRange(-1.0, 1.0));
  c->add_option("--seed", a.seed, "split seed")->check(kSeed);
  c->add_flag("--quiet", a.quiet, "no progress lines");
}

}  // namespace

void add_head_command(CLI::App& app) {
  auto a = std::make_shared<HeadArgs>();
  auto* head =
      app.add_subcommand("head", "Speech-driven head motion: features, corpus, train, synth, eval");
  head->require_subcommand(1);

  auto* f = head->add_subcommand("features", "Prosodic features of a WAV file as CSV");
  f->add_option("IN", a->in, "audio file")->required();
  f->add_option("--out", a->out, "features CSV")->required()->check(kOutputFile);
  set_subcommand_body(f, [a] { return run_features(*a); });

  auto* c = head->add_subcommand("corpus",
                                 "Generate a synthetic corpus (espeak-ng speech + head motion)");
  c->add_option("--out", a->out, "folder")->required()->check(kOutputFolder);
  c->add_option("--utterances", a->utterances, "how many")->check(CLI::Range(1, 10000));
  c->add_option("--speakers", a->speakers, "speaker styles (1..4)")->check(CLI::Range(1, 4));
  c->add_option("--seed", a->seed, "random seed")->check(kSeed);
  c->add_flag("--quiet", a->quiet, "no progress lines");
  set_subcommand_body(c, [a] { return run_corpus(*a); });

  auto* t = head->add_subcommand("train", "Train a model on the training split of a corpus");
  t->add_option("CORPUS", a->corpus, "corpus folder")->required();
  t->add_option("--out", a->out, "model file")->required()->check(kOutputFile);
  add_train_options(t, *a);
  set_subcommand_body(t, [a] { return run_train(*a); });

  auto* s = head->add_subcommand("synth", "Synthesize head poses for a WAV file");
  s->add_option("MODEL", a->model, "model file")->required();
  s->add_option("IN", a->in, "audio file")->required();
  s->add_option("--out", a->out, "poses CSV (time_s, yaw_deg, pitch_deg, roll_deg)")
      ->required()
      ->check(kOutputFile);
  s->add_option("--noise-deg", a->noise_deg, "override the model's noise amplitude")
      ->check(FiniteRange(0.0, 10.0));
  set_subcommand_body(s, [a] { return run_synth(*a); });

  auto* e = head->add_subcommand("eval",
                                 "Evaluate a model on the corpus utterances it was not trained on");
  e->add_option("MODEL", a->model, "model file")->required();
  e->add_option("CORPUS", a->corpus, "corpus folder")->required();
  set_subcommand_body(e, [a] { return run_eval(*a); });

  auto* tb = head->add_subcommand("table",
                                  "Train and evaluate the paper's eight configurations (Table 1)");
  tb->add_option("CORPUS", a->corpus, "corpus folder")->required();
  tb->add_option("--out", a->out, "also write the table (markdown) here")->check(kOutputFile);
  add_train_options(tb, *a);
  set_subcommand_body(tb, [a] { return run_table(*a); });
}

}  // namespace animrt::cli
