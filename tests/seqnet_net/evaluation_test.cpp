// Evaluation on held-out frames: the pieces are the trainer's held-out
// segments (a feature file without clips is one clip named "all"); on
// features that move linearly in time a model that adds that very step
// each frame generates the truth, linear extrapolation from three frames
// is exact and from one is not, feature-space interpolation is exact and
// vertex-space is not; the change per frame is the step's, and 0 for a
// model that never moves; a model of another template is refused; on a
// walking bar with its placement, the completion placed as `seq complete`
// places it is measured against linear vertex interpolation with nothing
// aligned, on the clips named, and the trainer's held-out line measures
// the same; a model whose placed completion is not finite is refused.

#include "animrt/learn/seqnet/evaluation.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <Eigen/Geometry>
#include <numbers>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/model_file.hpp"
#include "animrt/controllers/seqnet/output_check.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/held_out_completion.hpp"
#include "animrt/learn/seqnet/network.hpp"
#include "animrt/learn/seqnet/training.hpp"
#include "net_test_util.hpp"

namespace animrt::seqnet {
namespace {

constexpr int kFrames = 60;
constexpr float kStep[kFeatureDims] = {0.1F,  -0.06F, 0.08F,  0.03F, -0.05F,
                                       0.04F, 0.06F,  -0.02F, 0.05F};

// The bending bar's template and scale, its frames replaced by frame 0 plus
// t steps (normalised units, the same step at every vertex), two clips.
SequenceFeatures linear_features() {
  SequenceFeatures f = nettest::bending_bar(3, 5, 16);
  const FeatureFrame start = f.frames.front() * 0.5;
  f.frames.clear();
  f.placement.clear();  // made-up frames: no placement
  for (int t = 0; t < kFrames; ++t) {
    FeatureFrame x = start;
    for (int c = 0; c < kFeatureDims; ++c) x.row(c).array() += static_cast<double>(kStep[c]) * t;
    f.frames.push_back(x);
  }
  f.clips = {Clip{"a", 0, kFrames / 2, 25.0}, Clip{"b", kFrames / 2, kFrames / 2, 25.0}};
  return f;
}

// Every parameter 0 but the last decoder layer's bias: dX = step everywhere.
ModelFile step_model(const SequenceFeatures& f, float scale) {
  torch::manual_seed(3);
  ModelFile m;
  m.shape.kind = ModelKind::mesh;
  m.shape.vertex_count = f.vertex_count();
  m.shape.latent = 5;
  m.shape.hidden = 6;
  m.shape.window = 12;
  m.rest = f.rest;
  m.triangles = f.triangles;
  m.low.assign(f.scale.low.data(), f.scale.low.data() + f.scale.low.size());
  m.high.assign(f.scale.high.data(), f.scale.high.data() + f.scale.high.size());
  m.seed = 7;
  SeqNet net(m.shape, mesh_graph(m.shape.vertex_count, m.triangles));
  m.parameters = save_parameters(*net);
  for (NamedArray& a : m.parameters) {
    std::fill(a.values.begin(), a.values.end(), 0.0F);
    if (a.name == "decoder.4.self.bias") {
      for (int c = 0; c < kFeatureDims; ++c)
        a.values[static_cast<std::size_t>(c)] = scale * kStep[c];
    }
  }
  return m;
}

EvaluationOptions options() {
  EvaluationOptions o;
  o.held_out = 0.5;
  o.horizons = {2, 4};
  o.gap = 4;
  o.completion.retries = 0;
  o.change_frames = 14;  // more than a window: generation chains two
  return o;
}

TEST(SeqEvaluation, PiecesAreTheTrainersHeldOutSegments) {
  const SequenceFeatures f = linear_features();
  const std::string path = nettest::temp_path("evaluation_linear.feat");
  write_feature_file(path, f);
  const ModelFile m = step_model(f, 1.0F);
  const Evaluation e = evaluate(m, "m.model", f, options());
  const TrainingSet set = load_training_set({path}, m.seed, 0.5);
  std::vector<int> held;
  for (const Segment& s : set.segments) {
    if (s.held_out) held.push_back(s.count);
  }
  ASSERT_EQ(held.size(), e.pieces.size());
  int total = 0;
  for (std::size_t k = 0; k < held.size(); ++k) {
    EXPECT_EQ(e.pieces[k].count, held[k]);
    const Clip& p = e.pieces[k];
    const Clip& clip = p.first < kFrames / 2 ? f.clips[0] : f.clips[1];
    EXPECT_EQ(p.name, clip.name);
    EXPECT_LE(p.first + p.count, clip.first + clip.count);
    total += p.count;
  }
  EXPECT_EQ(total, kFrames / 2);

  // A feature file without clips (one input) is read as one clip named
  // "all", as the trainer reads it: held out by that name, it is every
  // frame; by the fraction, its piece is named "all" too.
  SequenceFeatures one = f;
  one.clips.clear();
  const std::string one_path = nettest::temp_path("evaluation_no_clips.feat");
  write_feature_file(one_path, one);
  ASSERT_TRUE(read_feature_file(one_path).clips.empty());
  EvaluationOptions o = options();
  o.horizons = {};  // only completion measured: the pieces are the point
  o.change_frames = 0;
  o.data_path = one_path;
  o.held_out_clips = {"all"};
  const Evaluation all = evaluate(m, "m.model", one, o);
  EXPECT_GT(all.completion.frames, 0);
  ASSERT_EQ(all.pieces.size(), 1U);
  EXPECT_EQ(all.pieces.front().name, "all");
  EXPECT_EQ(all.pieces.front().first, 0);
  EXPECT_EQ(all.pieces.front().count, kFrames);
  const TrainingSet whole = load_training_set({one_path}, m.seed, 0.5, {"all"});
  ASSERT_EQ(whole.segments.size(), 1U);
  EXPECT_TRUE(whole.segments.front().held_out);
  EXPECT_EQ(whole.segments.front().count, kFrames);
  o.held_out_clips.clear();
  const Evaluation by_fraction = evaluate(m, "m.model", one, o);
  ASSERT_EQ(by_fraction.pieces.size(), 1U);
  EXPECT_EQ(by_fraction.pieces.front().name, "all");
  EXPECT_EQ(by_fraction.pieces.front().count, kFrames / 2);
}

TEST(SeqEvaluation, TheTrueStepGeneratesTheTruthAndBaselinesBehave) {
  const SequenceFeatures f = linear_features();
  const Evaluation e = evaluate(step_model(f, 1.0F), "m.model", f, options());
  ASSERT_EQ(e.generation.size(), 4U);
  const double tiny = 1e-5 * e.diagonal;
  for (const GenerationRow& r : e.generation) {
    EXPECT_GT(r.frames, 0);
    EXPECT_LT(r.learned, tiny) << r.initial << " " << r.horizon;
    if (r.initial == 3) {
      EXPECT_LT(r.extrapolated, tiny) << r.horizon;
    } else {
      EXPECT_GT(r.extrapolated, 100 * tiny) << r.horizon;  // the first frame repeated
    }
  }
  EXPECT_GT(e.generation[1].extrapolated, e.generation[0].extrapolated);  // further, worse
  ASSERT_GT(e.completion.frames, 0);
  EXPECT_EQ(e.completion.frames, 4 * e.completion.gaps);
  EXPECT_LT(e.completion.feature_linear, tiny);
  EXPECT_GT(e.completion.vertex_linear, 100 * tiny);

  // The step model against a wrong step: generation errs.
  const Evaluation wrong = evaluate(step_model(f, 1.5F), "m.model", f, options());
  EXPECT_GT(wrong.generation[1].learned, 100 * tiny);
}

TEST(SeqEvaluation, ChangePerFrameIsTheStepsAndZeroWhenFrozen) {
  const SequenceFeatures f = linear_features();
  const EvaluationOptions o = options();
  const Evaluation e = evaluate(step_model(f, 1.0F), "m.model", f, o);
  ASSERT_EQ(e.change_generated.size(), 14U);
  Eigen::Map<const Eigen::VectorXf> step(kStep, kFeatureDims);
  const double step_norm = step.cast<double>().norm() * std::sqrt(f.vertex_count());
  for (int t : {0, 5, 13}) {
    double expected = 0;
    int starts = 0;
    for (const Clip& p : e.pieces) {
      for (int s = p.first; s < p.first + p.count; ++s, ++starts) {
        FeatureFrame x = f.frames[static_cast<std::size_t>(s)];
        for (int c = 0; c < kFeatureDims; ++c)
          x.row(c).array() += static_cast<double>(kStep[c]) * t;
        expected += step_norm / x.norm();
      }
    }
    EXPECT_NEAR(e.change_generated[static_cast<std::size_t>(t)], expected / starts, 1e-4) << t;
  }
  EXPECT_EQ(e.change_starts, kFrames / 2);
  EXPECT_GT(e.change_truth, 0.0);
  const Evaluation frozen = evaluate(step_model(f, 0.0F), "m.model", f, o);
  for (double c : frozen.change_generated) EXPECT_EQ(c, 0.0);
}

TEST(SeqEvaluation, AnotherTemplateIsRefused) {
  const SequenceFeatures f = linear_features();
  ModelFile m = step_model(f, 1.0F);
  m.rest(0, 0) += 0.1;
  try {
    evaluate(m, "m.model", f, options());
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another template"), std::string::npos) << e.what();
  }
}

// A bar (frame 0, the template) then two clips of 21 frames, both moving
// at one constant velocity: "straight" keeps its pose, "turning" also turns
// about its own centroid by 12 degrees a frame. Absolute frames, so the
// features carry their placement.
SequenceFeatures walking_bar() {
  MeshSequence s = make_bar(3, 5, 4.0);
  const Positions rest = s.frames.front();
  const Eigen::Vector3d centre = rest.rowwise().mean();
  const Eigen::Vector3d velocity(0.05, 0.02, 0.0);
  for (const double turn : {0.0, std::numbers::pi / 15}) {
    for (int t = 0; t < 21; ++t) {
      const Eigen::Matrix3d r =
          Eigen::AngleAxisd(turn * t, Eigen::Vector3d::UnitX()).toRotationMatrix();
      s.frames.push_back(((r * (rest.colwise() - centre)).colwise() + centre).colwise() +
                         velocity * t);
    }
  }
  SequenceFeatures f = compute_features(s);
  f.clips = {Clip{"straight", 1, 21, 25.0}, Clip{"turning", 22, 21, 25.0}};
  return f;
}

TEST(SeqEvaluation, PlacedCompletionAgainstLinearVertexInterpolationOnNamedClips) {
  const SequenceFeatures f = walking_bar();
  const std::string path = nettest::temp_path("evaluation_walking_bar.feat");
  write_feature_file(path, f);
  // An untrained model as training starts it: the decoder's last layer at
  // zero, so blended completion is linear interpolation of the key features.
  ModelFile m = load_training_set({path}, 7).description;
  ASSERT_EQ(m.shape.placement_nodes, 1);
  m.shape.latent = 5;
  m.shape.hidden = 6;
  m.shape.window = 12;
  m.seed = 7;
  torch::manual_seed(3);
  SeqNet net(m.shape, mesh_graph(m.shape.vertex_count, m.triangles));
  net->zero_output_layer();
  m.parameters = save_parameters(*net);
  EvaluationOptions o = options();
  o.horizons = {2};
  o.change_frames = 0;
  o.data_path = path;
  const auto placed = [&](const ModelFile& model, const std::string& clip) {
    o.held_out_clips = {clip};
    const Evaluation e = evaluate(model, "m.model", f, o);
    EXPECT_EQ(e.pieces.size(), 1U);
    EXPECT_EQ(e.pieces.front().name, clip);
    EXPECT_EQ(e.pieces.front().count, 21);
    EXPECT_EQ(e.completion.placed_frames, 16);  // 4 gaps of 4 frames
    return e.completion;
  };
  // Straight on: the figure where it is, interpolated either way.
  const CompletionRow straight = placed(m, "straight");
  EXPECT_LT(straight.placed, 1e-5);
  EXPECT_LT(straight.placed_vertex_linear, 1e-9);
  // Turning: the features turn the bar, its vertices' straight lines cut
  // the corner (60 degrees between keys).
  const CompletionRow turning = placed(m, "turning");
  EXPECT_LT(turning.placed, 1e-5);
  EXPECT_GT(turning.placed_vertex_linear, 0.02);
  // The trainer's held-out line measures the same.
  const HeldOutCompletion held =
      measure_held_out_completion(m, load_training_set({path}, 7, 0.2, {"turning"}), o.gap);
  EXPECT_EQ(held.gap, o.gap);
  EXPECT_NEAR(held.placed, turning.placed, 1e-12);
  EXPECT_NEAR(held.placed_interpolation, turning.placed_vertex_linear, 1e-12);
  // A model whose every step adds a change completes off the truth, and
  // worse than the vertices' straight lines.
  ModelFile off = m;
  bool found = false;
  for (NamedArray& a : off.parameters) {
    if (a.name != "decoder.4.self.bias") continue;
    std::fill(a.values.begin(), a.values.end(), 0.05F);
    found = true;
  }
  ASSERT_TRUE(found);
  EXPECT_GT(placed(off, "straight").placed, 0.01);
  EXPECT_GT(placed(off, "turning").placed, turning.placed_vertex_linear);
  // A model file whose placement nodes' range is finite but vast (up to
  // 1e300): the file is read and its outputs check finite, but a float's
  // rounding of a normalised key, scaled back, is a velocity of some 1e291
  // per frame, and the placed in-betweens' error overflows. One error
  // naming the model, not a figure that is no number.
  ModelFile vast = m;
  const auto n = static_cast<std::size_t>(9 * vast.shape.vertex_count);
  ASSERT_EQ(vast.low.size(), n + 9);
  for (std::size_t i = n; i < vast.low.size(); ++i) {
    vast.low[i] = -1.0;
    vast.high[i] = 1e300;
  }
  const std::string vast_path = nettest::temp_path("evaluation_vast.model");
  write_model_file(vast_path, vast);
  o.held_out_clips = {"turning"};
  try {
    evaluate(read_checked_model(vast_path), vast_path, f, o);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(vast_path), std::string::npos) << what;
    EXPECT_NE(what.find("its placed completion is not finite"), std::string::npos) << what;
  }
  // A name that is no clip is refused, naming the file and the clips.
  o.held_out_clips = {"walk"};
  try {
    evaluate(m, "m.model", f, o);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("no clip named 'walk' (the clips: straight, turning)"), std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace animrt::seqnet
