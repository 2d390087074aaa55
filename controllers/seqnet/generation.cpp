#include "animrt/controllers/seqnet/generation.hpp"

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"

namespace animrt::seqnet {

FrameMatrix mesh_features(const ModelFile& model, const std::string& model_path,
                          const std::vector<Positions>& frames,
                          const std::vector<std::array<int, 3>>& triangles) {
  for (const Positions& p : frames) {
    check_model_mesh(model, model_path, static_cast<int>(p.cols()), triangles);
  }
  MeshSequence seq;
  seq.triangles = model.triangles;
  seq.frames.push_back(model.rest);
  for (const Positions& p : frames) seq.frames.push_back(p);
  const SequenceFeatures f = compute_features(seq);
  FrameMatrix out(model.shape.input_dims(), static_cast<Eigen::Index>(frames.size()));
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const FeatureFrame raw = f.raw(static_cast<int>(k) + 1);
    out.col(static_cast<Eigen::Index>(k)) = Eigen::Map<const Eigen::VectorXd>(raw.data(), raw.size());
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
                                      const FrameMatrix& keys_features, const Completion& completion,
                                      int gap) {
  const Reconstructor solver(model.rest, model.triangles);
  const Neighbourhood& ring = solver.neighbourhood();
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
