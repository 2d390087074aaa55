#pragma once
// Tiny data sets for the sequence-network tests: a joint-angle CSV of
// smooth cyclic motion and the feature file of a small bending bar.

#include <torch/torch.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/learn/seqnet/shapes.hpp"
#include "animrt/learn/seqnet/training.hpp"

namespace nettest {

inline std::string temp_path(const std::string& name) {
  const char* base = std::getenv("TMPDIR");
  const std::filesystem::path dir = std::filesystem::path(base ? base : "/tmp") / "seqnet_net";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

// Training options of a tiny network (one thread, 8-frame windows, a few
// thousand parameters) that learns in a few dozen iterations.
inline animrt::seqnet::TrainOptions tiny_options(const std::string& data, const std::string& out) {
  animrt::seqnet::TrainOptions o;
  o.data = {data};
  o.out = temp_path(out);
  o.threads = 1;
  o.batch = 4;
  o.window = 8;
  o.latent = 8;
  o.hidden = 16;
  o.dense_width = 16;
  o.learning_rate = 3e-3;
  o.report_every = 0;
  o.checkpoint_every = 1000;
  return o;
}

// Three joints swinging with phase offsets, plus the corpus's extra columns
// (which are not joints), `frames` rows at 25 fps.
inline std::string write_joint_csv(const std::string& name, int frames,
                                   const std::string& joints = "hip,knee,ankle") {
  const std::string path = temp_path(name);
  std::ofstream out(path);
  out << "time_s," << joints << ",torso_x,torso_yaw\n";
  for (int f = 0; f < frames; ++f) {
    const double t = f / 25.0;
    const double w = 2.0 * M_PI * 1.25;
    out << t << ',' << 0.5 * std::sin(w * t) << ',' << 0.8 + 0.3 * std::cos(w * t) << ','
        << -0.2 * std::sin(w * t + 1.0) << ',' << 0.1 * t << ",0\n";
  }
  return path;
}

// A bar of rings x around vertices bending to and fro about x, its features.
inline animrt::seqnet::SequenceFeatures bending_bar(int rings, int around, int frames) {
  using namespace animrt::seqnet;
  MeshSequence s = make_bar(rings, around, 4.0);
  const Positions rest = s.frames.front();
  s.frames.clear();
  for (int f = 0; f < frames; ++f) {
    const double amplitude = 0.6 * std::sin(2.0 * M_PI * f / 16.0);
    Positions p = rest;
    for (Eigen::Index v = 0; v < p.cols(); ++v) {
      const double a = amplitude * p(2, v) / 4.0;
      const double y = p(1, v), z = p(2, v);
      p(1, v) = std::cos(a) * y - std::sin(a) * z;
      p(2, v) = std::sin(a) * y + std::cos(a) * z;
    }
    s.frames.push_back(p);
  }
  return compute_features(s);
}

inline std::string write_bar_features(const std::string& name, int rings, int around, int frames) {
  const std::string path = temp_path(name);
  animrt::seqnet::write_feature_file(path, bending_bar(rings, around, frames));
  return path;
}

}  // namespace nettest
