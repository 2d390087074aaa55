#pragma once
// Prosodic features: pitch (F0) and RMS energy on 25 ms windows, F0 filled
// through unvoiced gaps by a cubic spline, plus first and second derivatives
// of both: the 6-D observation of the head-motion HMMs.
//
// Frame rate: one frame every 1/120 s (a 25 ms window advanced by 8.33 ms,
// the paper's 120 frames per second, so feature frames line up with 120 Hz
// pose frames). Frame i covers samples [i*hop, i*hop + window) of the audio
// resampled to `sample_rate`, and its time is the window's centre:
//   t_i = i / frame_rate_hz + window_s / 2.

#include <Eigen/Core>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/controllers/head/audio.hpp"

namespace animrt::head {

constexpr int kFeatureDim = 6;  // f0, energy, d f0, d energy, dd f0, dd energy

// The observation's pitch and energy are on logarithmic scales: F0 in
// semitones above 100 Hz and energy in dB relative to full scale (floored at
// -60 dB). An accent raises F0 by about the same number of semitones in a low
// and a high voice, so the HMMs learn intonation that carries across
// speakers, while the absolute level still tells voices apart.
constexpr double kF0ReferenceHz = 100.0;
constexpr double kEnergyFloorDb = -60.0;
double f0_semitones(double f0_hz);
double energy_db(double rms);

struct FeatureConfig {
  int sample_rate = 24000;       // analysis rate; audio is resampled to it
  double window_s = 0.025;       // analysis window
  double frame_rate_hz = 120.0;  // hop = sample_rate / frame_rate_hz samples (must be whole)
  std::string method = "yin";    // aubio pitch method: yin, yinfast, yinfft
  double f0_min_hz = 80.0;       // a 25 ms YIN window sees two periods down to 80 Hz
  double f0_max_hz = 500.0;
  double voicing_threshold = 0.8;  // aubio confidence (1 - YIN dip) to call a frame voiced
  double silence_db = -45.0;       // below this level a frame is unvoiced
  int delta_window = 2;            // regression half-width (frames) of the derivatives

  int hop_samples() const;
  int window_samples() const;
  // Time of frame 0's centre.
  double first_frame_time_s() const;
  // Throws std::invalid_argument when the numbers do not fit together.
  void validate() const;
};

// One analysis window's raw measurements.
struct RawFrame {
  double f0_hz = 0.0;   // 0 when unvoiced
  double energy = 0.0;  // RMS of the window about its mean (DC removed)
  double confidence = 0.0;
  bool voiced = false;
};

// Streaming pitch and energy: push samples at config.sample_rate in blocks of
// any size; every completed window yields one RawFrame. Wraps aubio.
class PitchEnergyTracker {
 public:
  explicit PitchEnergyTracker(const FeatureConfig& config);
  ~PitchEnergyTracker();
  PitchEnergyTracker(const PitchEnergyTracker&) = delete;
  PitchEnergyTracker& operator=(const PitchEnergyTracker&) = delete;

  // Appends one RawFrame per completed window to `out`.
  void push(std::span<const float> samples, std::vector<RawFrame>& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Offline features of a whole utterance.
struct FeatureTrack {
  double frame_rate_hz = 120.0;
  double t0_s = 0.0;  // time of frame 0
  std::vector<RawFrame> raw;
  std::vector<double> f0_filled;  // Hz, spline through voiced frames
  // frames x 6: f0 (semitones of f0_filled), energy (dB), and their first and
  // second derivatives per second.
  Eigen::MatrixXd features;
  std::size_t size() const { return raw.size(); }
  double time(std::size_t i) const { return t0_s + static_cast<double>(i) / frame_rate_hz; }
};

FeatureTrack extract_features(const Audio& audio, const FeatureConfig& config);
FeatureTrack extract_features_file(const std::string& wav_path, const FeatureConfig& config);

// Regression derivatives (per second) of each column, edge frames replicated:
//   d_t = rate * sum_k k (c_{t+k} - c_{t-k}) / (2 sum_k k^2),  k = 1..window.
Eigen::MatrixXd deltas(const Eigen::MatrixXd& x, int window, double frame_rate_hz);

// Writes the features CSV: time_s, f0_hz (0 unvoiced), energy (RMS), voiced,
// f0_filled_hz, then the observation: f0_st, energy_db, d_f0_st, d_energy_db,
// dd_f0_st, dd_energy_db.
void write_features_csv(const std::string& path, const FeatureTrack& track);

}  // namespace animrt::head
