// Offline synthesis of the shipped utterance with the shipped model, stage by
// stage (pitch, energy, voicing, the six features, the decoded clusters and
// the head poses), against a reference written by the straightforward
// implementation: work done to make the analysis fast must not change what
// it computes. After a deliberate change of the analysis, rewrite the
// reference with ANIMRT_HEAD_GOLDEN_WRITE=tests/head/synthesis_golden.csv.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/controllers/head/model.hpp"
#include "animrt/controllers/head/synthesis.hpp"

namespace animrt::head {
namespace {

// One line per feature frame ("f", raw pitch and energy, voicing, the six
// features, the cluster) and per pose ("p", time and angles).
std::vector<std::vector<double>> golden_rows(const HeadModel& model, const Audio& audio) {
  const FeatureTrack track = extract_features(audio, model.features);
  const std::vector<int> clusters = decode_track(model, track);
  const PoseTrack poses = synthesize(model, track);
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < track.size(); ++i) {
    const RawFrame& r = track.raw[i];
    std::vector<double> row{0, r.f0_hz, r.energy, r.confidence, r.voiced ? 1.0 : 0.0};
    for (int c = 0; c < kFeatureDim; ++c) row.push_back(track.features(static_cast<long>(i), c));
    row.push_back(clusters.at(i));
    rows.push_back(std::move(row));
  }
  for (std::size_t j = 0; j < poses.size(); ++j) {
    const Euler& e = poses.poses[j];
    rows.push_back({1, poses.times[j], e.yaw, e.pitch, e.roll});
  }
  return rows;
}

void write_golden(const std::string& path, const std::vector<std::vector<double>>& rows) {
  std::ofstream out(path);
  char buf[32];
  for (const auto& row : rows) {
    out << (row[0] == 0 ? 'f' : 'p');
    for (std::size_t c = 1; c < row.size(); ++c) {
      std::snprintf(buf, sizeof buf, ",%.12g", row[c]);
      out << buf;
    }
    out << '\n';
  }
}

std::vector<std::vector<double>> read_golden(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row{line.at(0) == 'f' ? 0.0 : 1.0};
    std::stringstream ss(line.substr(2));
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::strtod(cell.c_str(), nullptr));
    rows.push_back(std::move(row));
  }
  return rows;
}

TEST(Golden, OfflineSynthesisOfTheShippedUtteranceIsUnchanged) {
  const std::string src = ANIMRT_SOURCE_DIR;
  const HeadModel model = load_model(src + "/configs/head/model.txt");
  const Audio audio = load_audio(src + "/configs/head/utterance.wav");
  const auto rows = golden_rows(model, audio);
  if (const char* out = std::getenv("ANIMRT_HEAD_GOLDEN_WRITE")) write_golden(out, rows);
  const auto want = read_golden(src + "/tests/head/synthesis_golden.csv");
  ASSERT_EQ(rows.size(), want.size());
  // The reference keeps 12 significant digits: a value may move by its
  // rounding there and no more (small energies too, so relative).
  constexpr double kRelative = 1e-9, kAbsolute = 1e-12;
  int mismatches = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), want[i].size()) << "row " << i;
    for (std::size_t c = 0; c < rows[i].size(); ++c) {
      const double tol = kRelative * std::abs(want[i][c]) + kAbsolute;
      if (std::abs(rows[i][c] - want[i][c]) > tol && ++mismatches <= 10) {
        ADD_FAILURE() << "row " << i << " column " << c << ": " << rows[i][c] << " against "
                      << want[i][c];
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
}

}  // namespace
}  // namespace animrt::head
