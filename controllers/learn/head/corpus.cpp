#include "animrt/learn/head/corpus.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::head {
namespace {

void refuse_unreadable(const std::string& path) {
  const std::string problem = input_file_problem(path, kMaxMediaFileBytes);
  if (!problem.empty())
    throw InputError(Location{path, 0, 0}, "",
                     problem == kFileMissing ? "is a broken link" : problem);
}

}  // namespace

std::vector<Utterance> list_corpus(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(Location{dir, 0, 0}, "", "corpus folder not found");
  std::vector<fs::path> wavs;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".wav") continue;
    // A recording that is a FIFO, a device or a link to one is refused by
    // name: skipping it would shrink the corpus without a word.
    refuse_unreadable(entry.path().string());
    wavs.push_back(entry.path());
  }
  std::sort(wavs.begin(), wavs.end());
  if (wavs.empty()) throw InputError(Location{dir, 0, 0}, "", "no .wav files in the corpus folder");
  std::vector<Utterance> out;
  for (const auto& w : wavs) {
    Utterance u;
    u.name = w.stem().string();
    u.audio_path = w.string();
    for (const char* ext : {".csv", ".bvh", ".markers.csv"}) {
      const fs::path p = w.parent_path() / (u.name + ext);
      if (input_file_problem(p.string(), kMaxMediaFileBytes) == kFileMissing) continue;
      refuse_unreadable(p.string());
      u.pose_path = p.string();
      break;
    }
    if (u.pose_path.empty()) {
      throw InputError(Location{u.audio_path, 0, 0}, "",
                       "no head-pose file for this utterance (expected " + u.name + ".csv, " +
                           u.name + ".bvh or " + u.name + ".markers.csv beside it)");
    }
    out.push_back(std::move(u));
  }
  return out;
}

PreparedUtterance prepare_utterance(const Utterance& u, const FeatureConfig& config) {
  PreparedUtterance p;
  p.name = u.name;
  p.track = extract_features_file(u.audio_path, config);
  const PoseTrack poses = load_pose_file(u.pose_path);
  p.poses.resize(static_cast<Eigen::Index>(p.track.size()), 3);
  for (std::size_t i = 0; i < p.track.size(); ++i) {
    const Euler e = poses.at(p.track.time(i));
    p.poses.row(static_cast<Eigen::Index>(i)) << e.yaw, e.pitch, e.roll;
  }
  return p;
}

std::vector<PreparedUtterance> prepare_corpus(const std::vector<Utterance>& utterances,
                                              const FeatureConfig& config) {
  std::vector<PreparedUtterance> out;
  out.reserve(utterances.size());
  for (const auto& u : utterances) out.push_back(prepare_utterance(u, config));
  return out;
}

CorpusSplit split_corpus(const std::vector<Utterance>& utterances, double train_fraction,
                         std::uint64_t seed) {
  std::vector<Utterance> shuffled = utterances;
  std::mt19937_64 rng(seed);
  // Fisher-Yates with our own draws: std::shuffle's order differs between
  // standard libraries, and the split must be the same everywhere.
  for (std::size_t i = shuffled.size(); i > 1; --i) {
    const std::size_t j = static_cast<std::size_t>(rng() % i);
    std::swap(shuffled[i - 1], shuffled[j]);
  }
  const std::size_t n = shuffled.size();
  std::size_t n_train =
      static_cast<std::size_t>(std::lround(train_fraction * static_cast<double>(n)));
  n_train = std::clamp<std::size_t>(n_train, 1, n >= 2 ? n - 1 : n);
  CorpusSplit split;
  split.train.assign(shuffled.begin(), shuffled.begin() + static_cast<std::ptrdiff_t>(n_train));
  split.test.assign(shuffled.begin() + static_cast<std::ptrdiff_t>(n_train), shuffled.end());
  return split;
}

}  // namespace animrt::head
