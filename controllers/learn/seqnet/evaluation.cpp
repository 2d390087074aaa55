#include "animrt/learn/seqnet/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "animrt/controllers/seqnet/placement_nodes.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/held_out.hpp"
#include "animrt/learn/seqnet/held_out_completion.hpp"
#include "animrt/learn/seqnet/interpolation.hpp"

namespace animrt::seqnet {
namespace {

Eigen::VectorXd column(const FeatureFrame& raw) {
  return Eigen::Map<const Eigen::VectorXd>(raw.data(), raw.size());
}

// The features of a model input column (the placement nodes after them left
// out: errors here are measured up to a translation per piece).
FeatureFrame frame_of(const Eigen::Ref<const Eigen::VectorXd>& c, int vertices) {
  return Eigen::Map<const FeatureFrame>(c.data(), kFeatureDims, vertices);
}

// Mean per-vertex distance after removing each piece's mean offset, in the
// data's units.
double vertex_error(const Positions& truth, const Positions& got, const Neighbourhood& ring) {
  const double diagonal = (truth.rowwise().maxCoeff() - truth.rowwise().minCoeff()).norm();
  return error_up_to_translation(truth, got, ring).mean * diagonal;
}

// Completion of every piece's keys as `seq complete` does it from key
// meshes, placed, against linear interpolation of the keys' vertices
// (the placed fields of CompletionRow).
void complete_placed(const ModelFile& model, const std::string& model_path,
                     const SequenceFeatures& data, const Reconstructor& solver,
                     const std::vector<Clip>& pieces, const EvaluationOptions& o,
                     SeqNetInference& net, CompletionRow& c) {
  PlacedCompletion sums;
  for (const Clip& p : pieces) {
    std::vector<Positions> frames;
    for (int f = p.first; f < p.first + p.count; ++f) {
      frames.push_back(reconstruct_frame(solver, data, f));
    }
    add_placed_completion(model, model_path, net, frames, o.gap, o.completion, sums);
  }
  if (sums.frames > 0 && !std::isfinite(sums.network)) {
    throw InputError(Location{model_path, 0, 0}, "model",
                     "its placed completion is not finite (a diverged or corrupt model)");
  }
  c.placed_frames = sums.frames;
  if (sums.frames == 0) return;
  c.placed = sums.network / sums.frames;
  c.placed_vertex_linear = sums.interpolation / sums.frames;
}

}  // namespace

Evaluation evaluate(const ModelFile& model, const std::string& model_path,
                    const SequenceFeatures& data, const EvaluationOptions& o) {
  if (model.shape.kind != ModelKind::mesh) {
    throw InputError(Location{model_path, 0, 0}, "model",
                     "a joint model: evaluation takes a mesh model");
  }
  check_model_mesh(model, model_path, data.vertex_count(), data.triangles);
  if (model.rest.cols() != data.rest.cols() || !model.rest.isApprox(data.rest, 1e-9)) {
    throw InputError(Location{model_path, 0, 0}, "template",
                     "trained on another template (frame 0) than the feature file's");
  }
  Evaluation e;
  const int n = static_cast<int>(data.frames.size());
  e.pieces = o.held_out_clips.empty() ? held_out_pieces(n, data.clips, o.held_out, model.seed, 0)
                                      : named_clips(data.clips, n, o.held_out_clips, o.data_path);
  if (e.pieces.empty()) {
    throw InputError(Location{model_path, 0, 0}, "held out", "no held-out frames in the data");
  }
  const Reconstructor solver(data.rest, data.triangles);
  const Neighbourhood& ring = solver.neighbourhood();
  SeqNetInference net(model, model_path);
  const int vertices = data.vertex_count();
  const std::vector<Eigen::VectorXd> track =
      model.shape.placement_nodes > 0 ? placement_track(data) : std::vector<Eigen::VectorXd>{};
  if (model.shape.placement_nodes > 0 &&
      (track.empty() || track.front().size() != 9 * model.shape.placement_nodes)) {
    throw InputError(Location{model_path, 0, 0}, "placement",
                     "the model has placement nodes the feature file does not fit (a version-1 "
                     "file, or other pieces)");
  }
  // Frame f as the model's input: its features, then its placement nodes.
  auto input = [&](int f) {
    Eigen::VectorXd c(net.dims());
    c.head(9 * vertices) = column(data.raw(f));
    if (!track.empty()) c.tail(track.front().size()) = track[static_cast<std::size_t>(f)];
    return c;
  };

  // The true meshes of the held-out frames (up to a translation per piece).
  std::map<int, Positions> truth;
  for (const Clip& p : e.pieces) {
    for (int f = p.first; f < p.first + p.count; ++f) {
      truth.emplace(f, solver.solve(data.raw(f)));
      const Positions& t = truth.at(f);
      e.diagonal += (t.rowwise().maxCoeff() - t.rowwise().minCoeff()).norm();
    }
  }
  e.diagonal /= static_cast<double>(truth.size());
  bool measured = false;

  // Table 1: generation from u initial frames against extrapolation.
  const int longest =
      o.horizons.empty() ? 0 : *std::max_element(o.horizons.begin(), o.horizons.end());
  for (int u : o.initial_frames) {
    std::vector<GenerationRow> rows;
    for (int h : o.horizons) rows.push_back(GenerationRow{u, h, 0, 0.0, 0.0});
    for (const Clip& p : e.pieces) {
      for (int s = p.first; s + u - 1 + longest < p.first + p.count; ++s) {
        FrameMatrix given(net.dims(), u);
        for (int k = 0; k < u; ++k) given.col(k) = input(s + k);
        const FrameMatrix all = net.generate(given, longest);
        const FeatureFrame last = data.raw(s + u - 1);
        const FeatureFrame before = u > 1 ? data.raw(s + u - 2) : last;
        for (GenerationRow& r : rows) {
          const int target = s + u - 1 + r.horizon;
          const Positions learned = solver.solve(frame_of(all.col(u - 1 + r.horizon), vertices));
          const Positions extrapolated = solver.solve(lerp_features(before, last, 1.0 + r.horizon));
          r.learned += vertex_error(truth.at(target), learned, ring);
          r.extrapolated += vertex_error(truth.at(target), extrapolated, ring);
          ++r.frames;
        }
      }
    }
    for (GenerationRow& r : rows) {
      if (r.frames == 0) continue;
      r.learned /= r.frames;
      r.extrapolated /= r.frames;
      e.generation.push_back(r);
      measured = true;
    }
  }

  // Completion: keys every gap + 1 frames from each piece's first frame.
  CompletionRow& c = e.completion;
  for (const Clip& p : e.pieces) {
    const int keys = (p.count - 1) / (o.gap + 1) + 1;
    if (keys < 2) continue;
    FrameMatrix key_frames(net.dims(), keys);
    for (int k = 0; k < keys; ++k) key_frames.col(k) = input(p.first + k * (o.gap + 1));
    const Completion done = net.complete(
        key_frames, std::vector<int>(static_cast<std::size_t>(keys - 1), o.gap), o.completion);
    for (int g = 0; g + 1 < keys; ++g) {
      const int k0 = p.first + g * (o.gap + 1), k1 = k0 + o.gap + 1;
      ++c.gaps;
      if (done.gaps[static_cast<std::size_t>(g)].merged) ++c.merged;
      for (int t = 1; t <= o.gap; ++t) {
        const Positions& want = truth.at(k0 + t);
        const double s = static_cast<double>(t) / (o.gap + 1);
        c.learned += vertex_error(
            want, solver.solve(frame_of(done.frames.col(g * (o.gap + 1) + t), vertices)), ring);
        c.feature_linear +=
            vertex_error(want, solver.solve(lerp_features(data.raw(k0), data.raw(k1), s)), ring);
        c.vertex_linear += vertex_error(want, lerp_positions(truth.at(k0), truth.at(k1), s), ring);
        ++c.frames;
      }
    }
  }
  if (model.shape.placement_nodes > 0 && !data.placement.empty()) {
    complete_placed(model, model_path, data, solver, e.pieces, o, net, c);
  }
  if (c.frames > 0) {
    c.learned /= c.frames;
    c.feature_linear /= c.frames;
    c.vertex_linear /= c.frames;
    measured = true;
  }

  // Fig. 2: change between consecutive generated frames from one initial
  // frame (every held-out frame a start), against the held-out frames' own.
  if (o.change_frames > 0) {
    e.change_generated.assign(static_cast<std::size_t>(o.change_frames), 0.0);
    int steps = 0;
    for (const Clip& p : e.pieces) {
      for (int f = p.first; f < p.first + p.count; ++f) {
        FrameMatrix given(net.dims(), 1);
        given.col(0) = input(f);
        const Eigen::MatrixXf x = net.normalise(net.generate(given, o.change_frames));
        for (int t = 0; t < o.change_frames; ++t) {
          e.change_generated[static_cast<std::size_t>(t)] +=
              (x.col(t + 1) - x.col(t)).norm() / std::max(1e-12F, x.col(t).norm());
        }
        ++e.change_starts;
        if (f + 1 < p.first + p.count) {
          const FeatureFrame& a = data.frames[static_cast<std::size_t>(f)];
          const FeatureFrame& b = data.frames[static_cast<std::size_t>(f + 1)];
          e.change_truth += (b - a).norm() / std::max(1e-12, a.norm());
          ++steps;
        }
      }
    }
    for (double& v : e.change_generated) v /= std::max(1, e.change_starts);
    e.change_truth /= std::max(1, steps);
    measured = true;
  }
  if (!measured) {
    throw InputError(Location{model_path, 0, 0}, "held out",
                     "the held-out pieces are too short for any measurement");
  }
  return e;
}

}  // namespace animrt::seqnet
