#include "animrt/controllers/seqnet/output_check.hpp"

#include <algorithm>
#include <cmath>

#include "animrt/core/error.hpp"

namespace animrt::seqnet {
namespace {

// Long enough to pass every layer and several LSTM steps; short enough that
// the check costs less than one real generation.
constexpr int kCheckFrames = 8;

std::string value_text(double v) {
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

}  // namespace

void check_model_output(const ModelFile& model, const std::string& file) {
  SeqNetInference net(model, file);
  const int dims = net.dims();
  const int frames = std::min(kCheckFrames, model.shape.window - 1);
  const char* where[] = {"low", "middle", "high"};
  for (int k = 0; k < 3; ++k) {
    FrameMatrix start(dims, 1);
    for (int i = 0; i < dims; ++i) {
      const double lo = model.low[static_cast<std::size_t>(i)];
      const double hi = model.high[static_cast<std::size_t>(i)];
      start(i, 0) = lo + 0.5 * k * (hi - lo);
    }
    for (const double sign : {1.0, -1.0}) {
      const FrameMatrix out = net.generate(start, frames, std::nullopt, sign);
      for (Eigen::Index c = 0; c < out.cols(); ++c) {
        for (Eigen::Index i = 0; i < out.rows(); ++i) {
          if (std::isfinite(out(i, c))) continue;
          throw InputError(Location{file, 0, 0}, "parameters",
                           "the network's output is not finite (" + value_text(out(i, c)) +
                               " at frame " + std::to_string(c) + ", dimension " +
                               std::to_string(i) + ") when it " +
                               (sign > 0 ? "generates forward" : "runs backward") +
                               " from its training range's " + where[k] +
                               "; its weights overflow (retrain or use another model)");
        }
      }
    }
  }
}

ModelFile read_checked_model(const std::string& file) {
  ModelFile model = read_model_file(file);
  check_model_output(model, file);
  return model;
}

void require_finite_frames(const FrameMatrix& frames, const std::string& file,
                           const std::vector<std::string>& names) {
  for (Eigen::Index c = 0; c < frames.cols(); ++c) {
    for (Eigen::Index i = 0; i < frames.rows(); ++i) {
      const double v = frames(i, c);
      if (std::isfinite(v)) continue;
      const std::string dimension = static_cast<std::size_t>(frames.rows()) == names.size()
                                        ? names[static_cast<std::size_t>(i)]
                                        : "dimension " + std::to_string(i);
      throw InputError(Location{file, 0, 0}, "output",
                       "the model computed a non-finite value (" + value_text(v) + ") for " +
                           dimension + " at frame " + std::to_string(c) + "; nothing was written");
    }
  }
}

}  // namespace animrt::seqnet
