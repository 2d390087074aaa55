// Training: the loss falls on tiny data (joints and mesh), runs repeat for a
// seed, a resumed run equals an uninterrupted one, the held-out split, and
// data or checkpoints that do not fit are refused.

#include "animrt/learn/seqnet/training.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>

#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/core/error.hpp"
#include "net_test_util.hpp"

namespace animrt::seqnet {
namespace {

using nettest::tiny_options;

double mean_total(const std::vector<LossRecord>& h, std::size_t from, std::size_t count) {
  double s = 0;
  for (std::size_t i = from; i < from + count; ++i) s += h[i].total;
  return s / static_cast<double>(count);
}

std::vector<LossRecord> history_of(const std::string& checkpoint) {
  const ModelFile m = read_model_file(checkpoint);
  for (const NamedArray& a : m.optimiser) {
    if (a.name != "history") continue;
    std::vector<LossRecord> out;
    for (std::size_t i = 0; i < a.values.size(); i += 5) {
      out.push_back(
          {a.values[i + 1], a.values[i + 2], a.values[i + 3], a.values[i + 4], a.values[i]});
    }
    return out;
  }
  return {};
}

TEST(SeqTraining, JointLossFallsOnATinyCorpus) {
  TrainOptions o = tiny_options(nettest::write_joint_csv("swing.csv", 80), "swing.model");
  o.iterations = 60;
  // From the paper's random output layer: the loss must fall by half. (From
  // the zeroed one it starts where holding the frame is, near where these
  // few iterations end.)
  o.zero_output = false;
  std::ostringstream log;
  const TrainResult r = train(o, log);
  EXPECT_EQ(r.iterations, 60);
  const std::vector<LossRecord> h = history_of(o.out + ".ckpt");
  ASSERT_EQ(h.size(), 60U);
  const double first = mean_total(h, 0, 5), last = mean_total(h, 55, 5);
  EXPECT_LT(last, 0.5 * first) << "first " << first << " last " << last;
  EXPECT_GE(r.held_out, 0.0);
  const ModelFile m = read_model_file(o.out);
  EXPECT_EQ(m.joint_names, (std::vector<std::string>{"hip", "knee", "ankle"}));
  EXPECT_TRUE(m.optimiser.empty());
  std::ifstream svg(o.out + ".svg");
  std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<polyline"), std::string::npos);
}

// Every held_out_every iterations and at the end a line compares held-out
// completion with linear interpolation; the model file keeps the last one
// and it decides the warning.
TEST(SeqTraining, PrintsHeldOutCompletionAgainstInterpolationAndKeepsIt) {
  TrainOptions o = tiny_options(nettest::write_joint_csv("progress.csv", 80), "progress.model");
  o.iterations = 25;
  o.held_out_every = 10;
  std::ostringstream log;
  const TrainResult r = train(o, log);
  const std::string text = log.str();
  for (int at : {10, 20, 25}) {
    const std::string head = "held out at iteration " + std::to_string(at) +
                             ": completion of 9-frame gaps ";  // 16 held-out frames
    const auto line = text.find(head);
    ASSERT_NE(line, std::string::npos) << text;
    EXPECT_NE(text.find(" than interpolation)", line), std::string::npos) << text;
  }
  EXPECT_EQ(text.find("held out at iteration 5:"), std::string::npos) << text;
  ASSERT_GT(r.held_out_completion, 0.0);
  ASSERT_GT(r.held_out_interpolation, 0.0);
  char numbers[128];
  std::snprintf(numbers, sizeof numbers, "9-frame gaps %.2f %%, linear interpolation %.2f %% (",
                100.0 * r.held_out_completion, 100.0 * r.held_out_interpolation);
  EXPECT_NE(text.find(std::string("held out at iteration 25: completion of ") + numbers),
            std::string::npos)
      << text;
  const ModelFile m = read_model_file(o.out);
  EXPECT_EQ(m.held_out_completion, r.held_out_completion);
  EXPECT_EQ(m.held_out_interpolation, r.held_out_interpolation);
  EXPECT_EQ(m.held_out_gap, 9);
  const std::string warning = interpolation_warning(m, o.out);
  EXPECT_EQ(warning.empty(), r.held_out_completion < r.held_out_interpolation) << warning;

  // OUT.best is the model of the lowest held-out completion printed.
  int best_at = 0;
  double best = 1e9;
  for (int at : {10, 20, 25}) {
    const std::string head =
        "held out at iteration " + std::to_string(at) + ": completion of 9-frame gaps ";
    const double value = std::stod(text.substr(text.find(head) + head.size()));
    if (value < best) best = value, best_at = at;
  }
  EXPECT_EQ(r.best_iteration, best_at);
  const ModelFile kept = read_model_file(o.out + ".best");
  EXPECT_EQ(kept.iteration, static_cast<std::uint64_t>(best_at));
  EXPECT_NEAR(100.0 * kept.held_out_completion, best, 0.005);
  EXPECT_NE(text.find("best held-out completion: iteration " + std::to_string(best_at) +
                      ", kept in " + o.out + ".best"),
            std::string::npos)
      << text;
}

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A resumed training measures the OUT.best it finds first and replaces it
// only with a better model; the run's end names the kept one. An OUT.best
// that cannot be read, or is of another training, is moved to
// OUT.best.stale with one line saying why, and the training goes on.
TEST(SeqTraining, AResumeKeepsABetterBestModel) {
  const std::string data = nettest::write_joint_csv("best.csv", 80);
  TrainOptions a = tiny_options(data, "best_a.model");
  a.iterations = 40;
  a.held_out_every = 10;
  std::ostringstream log;
  train(a, log);
  const ModelFile better = read_model_file(a.out + ".best");
  TrainOptions b = tiny_options(data, "best_b.model");
  b.iterations = 5;
  b.held_out_every = 5;
  EXPECT_EQ(train(b, log).best_iteration, 5);
  std::filesystem::copy_file(a.out + ".best", b.out + ".best",
                             std::filesystem::copy_options::overwrite_existing);
  b.resume = b.out + ".ckpt";
  b.iterations = 10;
  std::ostringstream resumed;
  const TrainResult r = train(b, resumed);
  ASSERT_LT(better.held_out_completion, r.held_out_completion) << resumed.str();  // the setup
  EXPECT_EQ(r.best_iteration, 0);
  EXPECT_EQ(r.kept_best_iteration, static_cast<int>(better.iteration));
  EXPECT_EQ(read_model_file(b.out + ".best").iteration, better.iteration);
  EXPECT_NE(resumed.str().find("best held-out completion: iteration " +
                               std::to_string(better.iteration) + " (an earlier run), kept in " +
                               b.out + ".best\n"),
            std::string::npos)
      << resumed.str();
  EXPECT_EQ(resumed.str().find("note:"), std::string::npos) << resumed.str();

  // Resumes with nothing left to train: the one measurement at the end
  // writes the best model once the stale one is moved aside.
  const std::string best = b.out + ".best", stale = best + ".stale";
  ModelFile other_window = better;
  other_window.shape.window = 16;
  ModelFile other_joints = better;
  other_joints.joint_names.back() = "toe";
  auto bytes_of = [](const ModelFile& m) {
    const std::vector<std::uint8_t> v = model_file_bytes(m);
    return std::string(v.begin(), v.end());
  };
  const std::string whole = bytes_of(better);
  const std::pair<std::string, std::string> cases[] = {
      {whole.substr(0, whole.size() / 2), "cannot be read: "},
      {bytes_of(other_window), "another network (window 16 against 8)"},
      {bytes_of(other_joints),
       "trained on another joint set: the data lacks toe; the model lacks ankle"}};
  for (const auto& [bytes, why] : cases) {
    std::filesystem::remove(stale);
    std::ofstream(best, std::ios::binary | std::ios::trunc) << bytes;
    std::ostringstream aside;
    const TrainResult s = train(b, aside);
    EXPECT_NE(aside.str().find("note: " + best + " is not a best model of this training: " + why),
              std::string::npos)
        << aside.str();
    EXPECT_NE(aside.str().find("; moved to " + stale + "\n"), std::string::npos) << aside.str();
    EXPECT_TRUE(file_text(stale) == bytes) << why;  // moved, not rewritten
    EXPECT_EQ(s.best_iteration, 10) << why;
    EXPECT_EQ(read_model_file(best).iteration, 10U) << why;
  }
}

TEST(SeqTraining, AModelNeverBetterThanInterpolationIsWarnedOf) {
  ModelFile m;
  m.iteration = 200;
  EXPECT_NE(interpolation_warning(m, "m.model").find("m.model: never measured against linear"),
            std::string::npos);
  m.held_out_completion = 0.023;
  m.held_out_interpolation = 0.0139;
  m.held_out_gap = 9;
  EXPECT_EQ(interpolation_warning(m, "m.model"),
            "warning: m.model: never measured better than linear interpolation on held-out data "
            "(2.30 % against 1.39 % for linear interpolation, 9-frame gaps, after 200 "
            "iterations); train it longer");
  m.held_out_completion = 0.01;
  EXPECT_EQ(interpolation_warning(m, "m.model"), "");
}

TEST(SeqTraining, MeshLossFallsOnATinyBar) {
  TrainOptions o = tiny_options(nettest::write_bar_features("bar.features", 5, 6, 48), "bar.model");
  o.iterations = 40;
  o.channels = 9;
  o.zero_output = false;  // as in JointLossFallsOnATinyCorpus
  std::ostringstream log;
  train(o, log);
  const std::vector<LossRecord> h = history_of(o.out + ".ckpt");
  ASSERT_EQ(h.size(), 40U);
  const double first = mean_total(h, 0, 5), last = mean_total(h, 35, 5);
  EXPECT_LT(last, 0.7 * first) << "first " << first << " last " << last;
  const ModelFile m = read_model_file(o.out);
  EXPECT_EQ(m.shape.kind, ModelKind::mesh);
  EXPECT_EQ(m.shape.vertex_count, 5 * 6 + 2);
  // The features carry their placement: the held-out line also gives the
  // completion placed against linear vertex interpolation.
  const std::string text = log.str();
  const auto line = text.find("held out at iteration 40: completion of 8-frame gaps ");
  ASSERT_NE(line, std::string::npos) << text;
  EXPECT_LT(text.find("; placed vertices ", line), text.find('\n', line)) << text;
}

TEST(SeqTraining, SameSeedRepeatsAndAResumeEqualsOneRun) {
  const std::string data = nettest::write_joint_csv("repeat.csv", 60);
  std::ostringstream log;
  TrainOptions a = tiny_options(data, "a.model");
  a.iterations = 6;
  train(a, log);
  TrainOptions b = tiny_options(data, "b.model");
  b.iterations = 6;
  train(b, log);
  TrainOptions c = tiny_options(data, "c.model");
  c.iterations = 3;
  c.checkpoint_every = 3;
  train(c, log);
  c.resume = c.out + ".ckpt";
  c.iterations = 6;
  train(c, log);
  TrainOptions d = tiny_options(data, "d.model");
  d.iterations = 6;
  d.seed = 2;
  train(d, log);
  const ModelFile ma = read_model_file(a.out), mb = read_model_file(b.out),
                  mc = read_model_file(c.out), md = read_model_file(d.out);
  ASSERT_EQ(ma.parameters.size(), mc.parameters.size());
  for (std::size_t k = 0; k < ma.parameters.size(); ++k) {
    EXPECT_EQ(ma.parameters[k].values, mb.parameters[k].values) << ma.parameters[k].name;
    EXPECT_EQ(ma.parameters[k].values, mc.parameters[k].values) << ma.parameters[k].name;
  }
  EXPECT_EQ(mc.iteration, 6U);
  EXPECT_NE(ma.parameters[0].values, md.parameters[0].values);
}

TEST(SeqTraining, OneFifthOfEachDatasetIsHeldOutInOneBlock) {
  const std::string one = nettest::write_joint_csv("split1.csv", 50);
  const std::string two = nettest::write_joint_csv("split2.csv", 30);
  const TrainingSet set = load_training_set({one, two}, 5);
  int held[2] = {0, 0}, total[2] = {0, 0}, blocks[2] = {0, 0};
  for (const Segment& s : set.segments) {
    total[s.dataset] += s.count;
    if (s.held_out) {
      held[s.dataset] += s.count;
      ++blocks[s.dataset];
    }
  }
  EXPECT_EQ(total[0], 50);
  EXPECT_EQ(total[1], 30);
  EXPECT_EQ(held[0], 10);
  EXPECT_EQ(held[1], 6);
  EXPECT_EQ(blocks[0], 1);
  EXPECT_EQ(blocks[1], 1);
  // Values normalised to [-0.95, 0.95] with both ends reached.
  float lo = 1, hi = -1;
  for (const Segment& s : set.segments) {
    for (float v : s.values) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  EXPECT_NEAR(lo, -0.95F, 1e-6);
  EXPECT_NEAR(hi, 0.95F, 1e-6);
}

// Named clips (a feature file's, or joint CSVs) are held out whole, e.g.
// the walks of another seed, and nothing else is; a name that is no clip
// is an error naming the option and the clips there are.
TEST(SeqTraining, NamedClipsAreHeldOutWhole) {
  SequenceFeatures f = nettest::bending_bar(3, 4, 40);
  f.clips = {Clip{"seed1", 0, 24, 25.0}, Clip{"seed99", 24, 16, 25.0}};
  const std::string path = nettest::temp_path("clips.features");
  write_feature_file(path, f);
  const TrainingSet set = load_training_set({path}, 5, 0.2, {"seed99"});
  int held = 0, trained = 0;
  for (const Segment& s : set.segments) (s.held_out ? held : trained) += s.count;
  EXPECT_EQ(held, 16);
  EXPECT_EQ(trained, 24);
  ASSERT_EQ(set.segments.size(), 2U);
  EXPECT_FALSE(set.segments[0].held_out);
  EXPECT_TRUE(set.segments[1].held_out);

  const std::string one = nettest::write_joint_csv("clip1.csv", 50);
  const std::string two = nettest::write_joint_csv("clip2.csv", 30);
  const TrainingSet joints = load_training_set({one, two}, 5, 0.2, {two});
  for (const Segment& s : joints.segments) EXPECT_EQ(s.held_out, s.dataset == 1) << s.dataset;
  try {
    load_training_set({path}, 5, 0.2, {"seed2"});
    FAIL();
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("--held-out-clip"), std::string::npos) << what;
    EXPECT_NE(what.find("no clip named 'seed2' (the clips: seed1, seed99)"), std::string::npos)
        << what;
  }
}

TEST(SeqTraining, CheckpointOfOtherDataIsRefused) {
  std::ostringstream log;
  TrainOptions o = tiny_options(nettest::write_joint_csv("ck.csv", 40), "ck.model");
  o.iterations = 2;
  train(o, log);
  TrainOptions other =
      tiny_options(nettest::write_joint_csv("ck_other.csv", 40, "hip,knee,toe"), "ck_other.model");
  other.resume = o.out + ".ckpt";
  other.iterations = 4;
  try {
    train(other, log);
    FAIL() << "resumed from another joint set";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(o.out + ".ckpt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("the data lacks ankle; the model lacks toe"),
              std::string::npos)
        << e.what();
  }
  // A final model is not a checkpoint.
  TrainOptions from_model = tiny_options(o.data.front(), "ck2.model");
  from_model.resume = o.out;
  from_model.iterations = 4;
  EXPECT_THROW(train(from_model, log), InputError);
}

TEST(SeqTraining, BadCsvAndTooShortDataAreClearErrors) {
  const std::string bad = nettest::temp_path("bad.csv");
  std::ofstream(bad) << "time_s,hip\n0,0.1\n0.04,oops\n";
  try {
    load_training_set({bad}, 1);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(bad + ":3:6: hip: \"oops\" is not a finite number"),
              std::string::npos)
        << e.what();
  }
  std::ostringstream log;
  TrainOptions o = tiny_options(nettest::write_joint_csv("short.csv", 10), "short.model");
  o.iterations = 1;
  try {
    train(o, log);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no training piece has 8 frames"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace animrt::seqnet
