#pragma once
// Streaming synthesis: audio in blocks of any size (a file played at real
// time, or live capture), poses out with a bounded delay.
//
// Pipeline and what each stage waits for (the latency budget):
//   resampling (libsamplerate, streaming)          a few samples
//   analysis window: a frame is complete at its end, half a window after
//     its time stamp                               window_s / 2      (12.5 ms)
//   F0 gap fill: an unvoiced run waits for the next voiced frame to be
//     spline-filled, at most max_gap_s; longer runs are released holding
//     the last F0                                  <= max_gap_s
//   derivatives: two regression windows ahead      2 * delta_window frames (33 ms)
//   fixed-lag Viterbi: frame t is committed when t + lag arrives
//                                                  decoder_lag_s
//   SQUAD: the segment between keys k and k+1 needs key k+2
//                                                  <= 2 / key_rate_hz (333 ms;
//                                                  none with causal smoothing)
// worst_case_latency_s() adds these up; the bench measures the real figure.
// Differences from offline synthesis: the F0 spline is local (through the
// last voiced frames and the first after the gap) instead of global, and the
// Viterbi path is committed with a fixed lag.

#include <samplerate.h>

#include <deque>
#include <memory>
#include <span>
#include <vector>

#include "animrt/controllers/head/decoder.hpp"
#include "animrt/controllers/head/model.hpp"
#include "animrt/controllers/head/rotation.hpp"

namespace animrt::head {

struct StreamOptions {
  int input_rate = 24000;      // rate of the pushed samples
  double decoder_lag_s = 0.2;  // fixed-lag Viterbi
  double max_gap_s = 0.15;     // longest unvoiced run filled by spline before holding
  // Causal smoothing instead of SQUAD: each output sample moves towards the
  // pose of the newest committed frame through two one-pole slerps of this
  // time constant, so a pose waits for no later key (SQUAD waits up to
  // 2 / key_rate_hz). With a short decoder lag and max_gap_s 0 the head
  // follows live speech within 0.15 s
  // (decoder_lag_s 0.07: the bound is 0.124 s plus the block).
  bool causal = false;
  double causal_time_constant_s = 0.06;
};

struct StreamPose {
  double t = 0;       // seconds of audio since the stream started
  Euler pose;         // degrees
  double energy = 0;  // RMS energy of the analysis frame at t (for the jaw)
};

class StreamingSynthesizer {
 public:
  StreamingSynthesizer(const HeadModel& model, StreamOptions options);
  ~StreamingSynthesizer();
  StreamingSynthesizer(const StreamingSynthesizer&) = delete;
  StreamingSynthesizer& operator=(const StreamingSynthesizer&) = delete;

  // Appends every pose that became final.
  void push(std::span<const float> block, std::vector<StreamPose>& out);
  // End of audio: flushes everything.
  void finish(std::vector<StreamPose>& out);

  double audio_time_s() const;  // seconds of audio pushed
  double worst_case_latency_s() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace animrt::head
