#include "animrt/controllers/seqnet/generation.hpp"

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/placement_nodes.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"

namespace animrt::seqnet {

FrameMatrix mesh_features(const ModelFile& model, const std::string& model_path,
                          const std::vector<Positions>& frames,
                          const std::vector<std::array<int, 3>>& triangles, double frames_apart) {
  for (const Positions& p : frames) {
    check_model_mesh(model, model_path, static_cast<int>(p.cols()), triangles);
  }
  MeshSequence seq;
  seq.triangles = model.triangles;
  seq.frames.push_back(model.rest);
  for (const Positions& p : frames) seq.frames.push_back(p);
  const SequenceFeatures f = compute_features(seq);
  FrameMatrix out(model.shape.input_dims(), static_cast<Eigen::Index>(frames.size()));
  const Eigen::Index n = 9 * Eigen::Index{model.shape.vertex_count};
  const Neighbourhood ring = build_neighbourhood(model.rest, model.triangles);
  const PlacementLayout layout = placement_layout(ring, model.rest);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const FeatureFrame raw = f.raw(static_cast<int>(k) + 1);
    const auto col = static_cast<Eigen::Index>(k);
    out.col(col).head(n) = Eigen::Map<const Eigen::VectorXd>(raw.data(), raw.size());
    if (model.shape.placement_nodes == 0) continue;
    // The body's velocity from the frame before (the first frame: to the
    // next one; a single frame: still).
    const std::size_t a = k > 0 ? k - 1 : 0,
                      b = k > 0 ? k : std::min<std::size_t>(1, frames.size() - 1);
    const Eigen::Vector3d v =
        (body_centroid(layout, ring, frames[b]) - body_centroid(layout, ring, frames[a])) /
        frames_apart;
    out.col(col).tail(out.rows() - n) = placement_values(layout, ring, frames[k], raw, v);
  }
  return out;
}

namespace {

// Vertex positions of one raw feature column, each connected piece placed by
// its lowest vertex at the template (as reconstruction does).
Positions solve_column(const Reconstructor& solver, const ModelFile& model,
                       const FrameMatrix& features, Eigen::Index k) {
  const FrameMatrix column = features.col(k);
  return solver.solve(
      Eigen::Map<const FeatureFrame>(column.data(), kFeatureDims, model.shape.vertex_count));
}

FeatureFrame raw_column(const ModelFile& model, const FrameMatrix& features, Eigen::Index k) {
  return Eigen::Map<const FeatureFrame>(features.col(k).data(), kFeatureDims,
                                        model.shape.vertex_count);
}

Eigen::VectorXd placement_column(const ModelFile& model, const FrameMatrix& features,
                                 Eigen::Index k) {
  const Eigen::Index n = 9 * Eigen::Index{model.shape.vertex_count};
  return features.col(k).tail(features.rows() - n);
}

// Frame k of `features` reconstructed and placed: the body's centroid at
// `centroid`, the other pieces where the placement nodes put them.
Positions placed_column(const Reconstructor& solver, const PlacementLayout& layout,
                        const ModelFile& model, const FrameMatrix& features, Eigen::Index k,
                        const Eigen::Vector3d& centroid) {
  Positions p = solve_column(solver, model, features, k);
  place_by_values(layout, solver.neighbourhood(), p, raw_column(model, features, k),
                  placement_column(model, features, k), centroid);
  return p;
}

Eigen::Vector3d velocity_of(const ModelFile& model, const FrameMatrix& features, Eigen::Index k) {
  return placement_column(model, features, k).head<3>();
}

// In-betweens placed by the completed placement nodes: the body moves by
// the completed velocities from key A, and what it lacks at key B is spread
// linearly over the gap, so both keys are met.
std::vector<Positions> placed_completion(const Reconstructor& solver, const ModelFile& model,
                                         const std::vector<Positions>& keys,
                                         const Completion& completion, int gap) {
  const PlacementLayout layout = placement_layout(solver.neighbourhood(), model.rest);
  std::vector<Positions> out{keys.front()};
  for (std::size_t k = 1; k < keys.size(); ++k) {
    const Eigen::Index first = static_cast<Eigen::Index>(k - 1) * (gap + 1);
    const Eigen::Vector3d a = body_centroid(layout, solver.neighbourhood(), keys[k - 1]);
    const Eigen::Vector3d b = body_centroid(layout, solver.neighbourhood(), keys[k]);
    std::vector<Eigen::Vector3d> path{a};
    for (int t = 1; t <= gap + 1; ++t) {
      path.push_back(path.back() + velocity_of(model, completion.frames, first + t));
    }
    const Eigen::Vector3d miss = b - path.back();
    for (int t = 1; t <= gap; ++t) {
      const Eigen::Vector3d c = path[static_cast<std::size_t>(t)] + miss * t / (gap + 1.0);
      out.push_back(placed_column(solver, layout, model, completion.frames, first + t, c));
    }
    out.push_back(keys[k]);
  }
  return out;
}

}  // namespace

std::vector<Positions> generate_mesh(const ModelFile& model, const std::string& model_path,
                                     const std::vector<Positions>& initial,
                                     const std::vector<std::array<int, 3>>& triangles,
                                     const GenerateOptions& options) {
  const auto u = static_cast<int>(initial.size());
  if (u < 1) throw InputError(Location{model_path, 0, 0}, "--init", "no initial frame");
  if (u >= model.shape.window) {
    throw InputError(Location{model_path, 0, 0}, "--init",
                     std::to_string(u) + " initial frames, the model's window is " +
                         std::to_string(model.shape.window) + " frames");
  }
  const FrameMatrix given = mesh_features(model, model_path, initial, triangles);
  SeqNetInference net(model, model_path);
  const FrameMatrix all = net.generate(given, options.frames, options.random_state);
  const Reconstructor solver(model.rest, model.triangles);
  const Neighbourhood& ring = solver.neighbourhood();
  if (model.shape.placement_nodes > 0) {
    // The body moves on by the generated velocities from the last initial
    // frame; the other pieces follow their anchors.
    const PlacementLayout layout = placement_layout(ring, model.rest);
    Eigen::Vector3d centroid = body_centroid(layout, ring, initial.back());
    std::vector<Positions> out = initial;
    for (Eigen::Index k = u; k < all.cols(); ++k) {
      centroid += velocity_of(model, all, k);
      out.push_back(placed_column(solver, layout, model, all, k, centroid));
    }
    return out;
  }
  const Eigen::Matrix3Xd offsets =
      piece_offsets(ring, initial.back(), solve_column(solver, model, all, u - 1));
  std::vector<Positions> out = initial;
  for (Eigen::Index k = u; k < all.cols(); ++k) {
    out.push_back(solve_column(solver, model, all, k));
    move_pieces(ring, out.back(), offsets);
  }
  return out;
}

std::vector<Positions> completed_mesh(const ModelFile& model, const std::vector<Positions>& keys,
                                      const FrameMatrix& keys_features,
                                      const Completion& completion, int gap) {
  const Reconstructor solver(model.rest, model.triangles);
  const Neighbourhood& ring = solver.neighbourhood();
  if (model.shape.placement_nodes > 0)
    return placed_completion(solver, model, keys, completion, gap);
  std::vector<Eigen::Matrix3Xd> offsets;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    offsets.push_back(piece_offsets(
        ring, keys[k], solve_column(solver, model, keys_features, static_cast<Eigen::Index>(k))));
  }
  std::vector<Positions> out;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (k > 0) {
      for (int t = 1; t <= gap; ++t) {
        out.push_back(solve_column(solver, model, completion.frames,
                                   static_cast<Eigen::Index>(k - 1) * (gap + 1) + t));
        const double s = static_cast<double>(t) / (gap + 1);
        move_pieces(ring, out.back(), (1.0 - s) * offsets[k - 1] + s * offsets[k]);
      }
    }
    out.push_back(keys[k]);
  }
  return out;
}

}  // namespace animrt::seqnet
